#include "variational_formation_core/manoeuvres/commanded_frame.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace vf {

Vector3 centroidVelocity(const Velocities& v) {
  Vector3 c = Vector3::Zero();
  if (v.cols() == 0) return c;
  for (Eigen::Index i = 0; i < v.cols(); ++i) c.head(v.rows()) += v.col(i);
  return c / static_cast<double>(v.cols());
}

Vector3 rotationRate(const Positions& q, const Velocities& v, double timeStep) {
  Vector3 rate = Vector3::Zero();
  const Eigen::Index n = q.cols();
  if (n < 2) return rate;
  const Positions before = q - timeStep * v;
  const Eigen::VectorXd cb = before.rowwise().mean();
  const Eigen::VectorXd ca = q.rowwise().mean();
  if (q.rows() == 2) {
    double cross = 0.0, dot = 0.0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Vector2d a = before.col(i) - cb, b = q.col(i) - ca;
      cross += a.x() * b.y() - a.y() * b.x();
      dot += a.dot(b);
    }
    if (cross != 0.0 || dot != 0.0) rate.z() = std::atan2(cross, dot) / timeStep;
    return rate;
  }
  // Kabsch: H = sum a_i b_i^T = U S V^T, R = V diag(1, 1, det(V U^T)) U^T.
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (Eigen::Index i = 0; i < n; ++i) cov += (before.col(i) - cb) * (q.col(i) - ca).transpose();
  if (cov.isZero(0.0)) return rate;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d fix = Eigen::Matrix3d::Identity();
  fix(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  const Eigen::Matrix3d r = svd.matrixV() * fix * svd.matrixU().transpose();
  const Eigen::AngleAxisd turn(r);
  return turn.axis() * (turn.angle() / timeStep);
}

double meanScaleError(const Formation& formation, const Positions& q, double scale) {
  const auto& edges = formation.edges();
  if (edges.empty()) return 0.0;
  double sum = 0.0;
  long counted = 0;
  for (const Edge& e : edges) {
    if (e.desiredDistance == 0.0) continue;  // no scale to compare with
    sum += (q.col(e.tail) - q.col(e.head)).norm() / e.desiredDistance;
    ++counted;
  }
  return counted == 0 ? 0.0 : sum / static_cast<double>(counted) - scale;
}

CommandedFrame commandedFrame(const CommandSchedule& schedule, long step, double timeStep) {
  CommandedFrame frame;
  const Command& now = schedule.at(step);
  frame.scale = now.scale;
  frame.velocity = now.velocity;
  const auto& entries = schedule.entries();
  for (std::size_t e = 0; e < entries.size() && entries[e].first < step; ++e) {
    const long end = e + 1 < entries.size() ? std::min(entries[e + 1].first, step) : step;
    const Vector3& w = entries[e].second.angularRate;
    const double angle = w.norm() * timeStep * static_cast<double>(end - entries[e].first);
    // Each interval turns by exp(omega* h) about the same axis: together, one angle.
    if (angle > 0.0) frame.rotation = Eigen::AngleAxisd(angle, w.normalized()).toRotationMatrix() * frame.rotation;
  }
  return frame;
}

void subtractCommandedMotion(const Command& command, const Positions& q, Velocities& v) {
  if (command.velocity.isZero(0.0) && !command.rotates()) return;
  const int d = static_cast<int>(q.rows());
  Vector3 centroid = Vector3::Zero();
  centroid.head(d) = q.rowwise().mean();
  for (Eigen::Index i = 0; i < q.cols(); ++i) {
    Vector3 r = Vector3::Zero();
    r.head(d) = q.col(i);
    const Vector3 u = command.velocity + command.angularRate.cross(r - centroid);
    v.col(i) -= u.head(d);
  }
}

}  // namespace vf
