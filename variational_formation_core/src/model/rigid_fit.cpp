#include "variational_formation_core/model/rigid_fit.hpp"

#include "variational_formation_core/common/invalid_input.hpp"

namespace vf {

RigidFit fitRigidMotion(const Positions& target, const Positions& source, bool allowReflection) {
  if (target.rows() != source.rows() || target.cols() != source.cols() || target.cols() == 0) {
    throw InvalidInput("fitRigidMotion: the point sets differ in size or are empty");
  }
  const Eigen::VectorXd a = target.rowwise().mean(), b = source.rowwise().mean();
  const Eigen::MatrixXd h = (source.colwise() - b) * (target.colwise() - a).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::MatrixXd& u = svd.matrixU();
  const Eigen::MatrixXd& v = svd.matrixV();
  Eigen::VectorXd signs = Eigen::VectorXd::Ones(h.rows());
  // det(V U^T) = -1 means the best orthogonal map reflects; a rotation flips the weakest axis.
  if (!allowReflection && (v * u.transpose()).determinant() < 0.0) signs(signs.size() - 1) = -1.0;
  RigidFit fit;
  fit.rotation = v * signs.asDiagonal() * u.transpose();
  fit.reflection = fit.rotation.determinant() < 0.0;
  fit.translation = a - fit.rotation * b;
  fit.squaredResidual = ((fit.rotation * source).colwise() + fit.translation - target).squaredNorm();
  return fit;
}

bool isMirrorImage(const Positions& q, const Positions& desired, double flatness) {
  if (desired.cols() <= desired.rows()) return false;  // d or fewer points lie in a hyperplane
  const Eigen::VectorXd extent =
      Eigen::JacobiSVD<Eigen::MatrixXd>(desired.colwise() - desired.rowwise().mean()).singularValues();
  if (!(extent(extent.size() - 1) > flatness * extent(0))) return false;
  return fitRigidMotion(q, desired, /*allowReflection=*/true).reflection;
}

}  // namespace vf
