#include "variational_formation_core/model/motion_parameters.hpp"

#include <algorithm>

namespace vf {

// doc/maths.md §9: the minimum-norm solution of E_i mu_i = q*_i - c*, E_i = [q*_i - q*_j]_j.
MotionParameters motionParameters(const Formation& formation, int agent) {
  const Positions& shape = formation.desiredShape();
  const int d = formation.dimension();
  const std::vector<Neighbour>& nbs = formation.neighbours(agent);
  Eigen::VectorXd centroid = Eigen::VectorXd::Zero(d);
  for (Eigen::Index i = 0; i < shape.cols(); ++i) centroid += shape.col(i);
  centroid /= static_cast<double>(shape.cols());
  const Eigen::VectorXd target = shape.col(agent) - centroid;

  MotionParameters result;
  Eigen::MatrixXd edges(d, static_cast<Eigen::Index>(nbs.size()));
  for (std::size_t e = 0; e < nbs.size(); ++e) {
    edges.col(static_cast<Eigen::Index>(e)) = shape.col(agent) - shape.col(nbs[e].agent);
  }
  Eigen::VectorXd mu = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(nbs.size()));
  int rank = 0;
  if (!nbs.empty()) {
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(edges);
    cod.setThreshold(1e-9);
    rank = static_cast<int>(cod.rank());
    mu = cod.solve(target);
  }
  result.weights.assign(mu.data(), mu.data() + mu.size());
  const double residual = nbs.empty() ? target.norm() : (edges * mu - target).norm();
  double size = 0.0;
  for (Eigen::Index i = 0; i < shape.cols(); ++i) size = std::max(size, (shape.col(i) - centroid).norm());
  result.exact = residual <= 1e-9 * std::max(size, 1e-300) || target.norm() == 0.0;
  if (!result.exact) {
    std::string list;
    for (const Neighbour& nb : nbs) list += (list.empty() ? "" : ", ") + std::to_string(nb.agent);
    result.problem = "agent " + std::to_string(agent) + " cannot know its offset from the centroid: its " +
                     std::to_string(nbs.size()) + " edge vector(s) (to agents " + (list.empty() ? "none" : list) +
                     ") span " + std::to_string(rank) + " of " + std::to_string(d) +
                     " dimensions and miss q*_i - c* (give it " + std::to_string(d) +
                     " neighbours in general position)";
  }
  return result;
}

void centroidOffset(const Formation& formation, const MotionParameters& parameters, int agent,
                    const Positions& q, double* out) {
  centroidOffsetFrom(formation, parameters, agent, q.col(agent).data(), [&q](int j) { return q.col(j).data(); }, out);
}

}  // namespace vf
