#include "variational_formation_core/model/formation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/sparse_spectrum.hpp"

namespace vf {

int rigidEdgeCount(int dimension, int agentCount) {
  return dimension * agentCount - dimension * (dimension + 1) / 2;
}

Formation::Formation(int dimension, Positions desiredShape,
                     const std::vector<std::pair<int, int>>& edges)
    : dimension_(dimension), desiredShape_(std::move(desiredShape)) {
  if (dimension != 2 && dimension != 3) {
    throw InvalidInput("dimension: must be 2 or 3, got " + std::to_string(dimension));
  }
  if (desiredShape_.rows() != dimension) {
    throw InvalidInput("desired_position: expected " + std::to_string(dimension) +
                       " coordinates per agent, got " + std::to_string(desiredShape_.rows()));
  }
  if (desiredShape_.cols() < 1) {
    throw InvalidInput("agents: at least one agent is required");
  }
  if (!desiredShape_.allFinite()) {
    throw InvalidInput("desired_position: values must be finite");
  }
  const int n = agentCount();
  neighbours_.assign(n, {});
  std::set<std::pair<int, int>> seen;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const int i = edges[e].first;
    const int j = edges[e].second;
    const std::string where = "edges[" + std::to_string(e) + "]";
    if (i < 0 || i >= n || j < 0 || j >= n) {
      throw InvalidInput(where + ": agent " + std::to_string(i < 0 || i >= n ? i : j) +
                         " does not exist (ids are 0.." + std::to_string(n - 1) + ")");
    }
    if (i == j) {
      throw InvalidInput(where + ": an edge must join two distinct agents, got [" +
                         std::to_string(i) + ", " + std::to_string(j) + "]");
    }
    if (!seen.insert({std::min(i, j), std::max(i, j)}).second) {
      throw InvalidInput(where + ": duplicate edge [" + std::to_string(i) + ", " +
                         std::to_string(j) + "]");
    }
    const double d2 = squaredDistance(desiredShape_.col(i).data(), desiredShape_.col(j).data(),
                                      dimension_);
    edges_.push_back({i, j, std::sqrt(d2), d2});
    neighbours_[i].push_back({j, d2});
    neighbours_[j].push_back({i, d2});
  }
}

double Formation::potential(const Positions& q) const {
  double v = 0.0;
  for (const Edge& e : edges_) {
    const double gamma =
        squaredDistance(q.col(e.tail).data(), q.col(e.head).data(), dimension_) -
        e.desiredDistanceSquared;
    v += 0.25 * gamma * gamma;
  }
  return v;
}

double Formation::agentPotential(int agent, const Positions& q, double scaleSquared) const {
  double v = 0.0;
  const double* qi = q.col(agent).data();
  for (const Neighbour& nb : neighbours_[agent]) {
    const double gamma =
        squaredDistance(qi, q.col(nb.agent).data(), dimension_) - scaleSquared * nb.desiredDistanceSquared;
    v += 0.125 * gamma * gamma;
  }
  return v;
}

// doc/maths.md §1, gradient; paper Section 6 per-agent formula with Gamma_ij = |q_i - q_j|^2 - d_ij^2.
void Formation::agentGradient(int agent, const Positions& q, double* out) const {
  agentGradientFrom(agent, q.col(agent).data(), [&q](int j) { return q.col(j).data(); }, out);
}

void Formation::agentScaledGradient(int agent, const Positions& q, double scaleSquared,
                                    double* out) const {
  agentScaledGradientFrom(agent, q.col(agent).data(), [&q](int j) { return q.col(j).data(); }, scaleSquared, out);
}

double Formation::scaledPotential(const Positions& q, double scaleSquared) const {
  double v = 0.0;
  for (const Edge& e : edges_) {
    const double gamma = squaredDistance(q.col(e.tail).data(), q.col(e.head).data(), dimension_) -
                         scaleSquared * e.desiredDistanceSquared;
    v += 0.25 * gamma * gamma;
  }
  return v;
}

void Formation::gradient(const Positions& q, Gradients& out) const {
  out.resize(dimension_, agentCount());
  for (int i = 0; i < agentCount(); ++i) agentGradient(i, q, out.col(i).data());
}

Eigen::MatrixXd Formation::hessian(const Positions& q) const {
  const int d = dimension_;
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(d * agentCount(), d * agentCount());
  for (const Edge& e : edges_) {
    const Eigen::VectorXd z = q.col(e.tail) - q.col(e.head);
    const double gamma = z.squaredNorm() - e.desiredDistanceSquared;
    // d/dz [gamma z] = gamma I + 2 z z^T
    const Eigen::MatrixXd block =
        gamma * Eigen::MatrixXd::Identity(d, d) + 2.0 * z * z.transpose();
    h.block(d * e.tail, d * e.tail, d, d) += block;
    h.block(d * e.head, d * e.head, d, d) += block;
    h.block(d * e.tail, d * e.head, d, d) -= block;
    h.block(d * e.head, d * e.tail, d, d) -= block;
  }
  return h;
}

Eigen::MatrixXd Formation::rigidityMatrix(const Positions& q) const {
  const int d = dimension_;
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(edges_.size()),
                                            d * agentCount());
  for (std::size_t row = 0; row < edges_.size(); ++row) {
    const Edge& e = edges_[row];
    const Eigen::VectorXd z = q.col(e.tail) - q.col(e.head);
    r.block(static_cast<Eigen::Index>(row), d * e.tail, 1, d) = z.transpose();
    r.block(static_cast<Eigen::Index>(row), d * e.head, 1, d) = -z.transpose();
  }
  return r;
}

int Formation::rigidityRank(const Positions& q) const {
  if (edges_.empty()) return 0;
  // Large formations: a sparse QR, O(edges) for the graphs formations use, where an SVD is
  // O((n d)^3) (doc/benchmarks.md).
  if (dimension_ * agentCount() > kDenseSpectrumLimit) return sparseRank(sparseRigidityMatrix(*this, q), 1e-9);
  // Divide and conquer: the same singular values as Jacobi to round-off, and 12 times faster on
  // the 400 x 400 matrix of a 200-agent ring (0.05 s against 0.61 s).
  Eigen::BDCSVD<Eigen::MatrixXd> svd(rigidityMatrix(q));
  const Eigen::VectorXd s = svd.singularValues();
  const double tol = 1e-9 * std::max(1.0, s(0));
  return static_cast<int>((s.array() > tol).count());
}

bool Formation::isInfinitesimallyRigid(const Positions& q) const {
  const int n = agentCount();
  if (n < 2) return true;
  if (n <= dimension_) {
    // Too few agents to span R^d: rigid iff complete (a simplex of lower dimension).
    const int pairs = n * (n - 1) / 2;
    return static_cast<int>(edges_.size()) == pairs && rigidityRank(q) == pairs;
  }
  return rigidityRank(q) == rigidEdgeCount(dimension_, n);
}

bool Formation::isMinimallyRigid(const Positions& q) const {
  const int n = agentCount();
  const int needed = n <= dimension_ ? n * (n - 1) / 2 : rigidEdgeCount(dimension_, n);
  return isInfinitesimallyRigid(q) && static_cast<int>(edges_.size()) == needed;
}

Eigen::VectorXd Formation::distanceErrors(const Positions& q, double scale) const {
  Eigen::VectorXd err(static_cast<Eigen::Index>(edges_.size()));
  for (std::size_t e = 0; e < edges_.size(); ++e) {
    const Edge& edge = edges_[e];
    err(static_cast<Eigen::Index>(e)) =
        std::sqrt(squaredDistance(q.col(edge.tail).data(), q.col(edge.head).data(), dimension_)) -
        scale * edge.desiredDistance;
  }
  return err;
}

double Formation::maxDistanceError(const Positions& q, double scale) const {
  if (edges_.empty()) return 0.0;
  return distanceErrors(q, scale).cwiseAbs().maxCoeff();
}

bool Formation::allSlowerThan(const Velocities& v, double maxSpeed) const {
  for (int i = 0; i < agentCount(); ++i) {
    if (!(v.col(i).norm() < maxSpeed)) return false;
  }
  return true;
}

double Formation::congruenceSlack(const Positions& q, double tolerance, double scale) const {
  const int n = agentCount();
  double slack = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      double desired = 0.0;
      const double error = pairError(q, i, j, scale, desired);
      // Negative exactly when error > tolerance * desired (two distinct doubles never differ
      // by 0), NaN when either is NaN: the first such pair ends the test.
      const double pair = tolerance * desired - error;
      if (!(pair >= 0.0)) return pair;
      slack = std::min(slack, pair);
    }
  }
  return slack;
}

double Formation::shapeError(const Positions& q, double scale) const {
  double worst = 0.0, desired = 0.0;
  for (int i = 0; i < agentCount(); ++i) {
    for (int j = i + 1; j < agentCount(); ++j) {
      const double error = pairError(q, i, j, scale, desired);
      if (std::isnan(error)) return error;  // NaN positions: NaN, not a small error
      worst = std::max(worst, error);
    }
  }
  return worst;
}

bool Formation::edgesWithin(const Positions& q, double tolerance, double scale) const {
  const Eigen::VectorXd errors = distanceErrors(q, scale);
  for (std::size_t e = 0; e < edges_.size(); ++e) {
    if (!(std::abs(errors(static_cast<Eigen::Index>(e))) <= tolerance * scale * edges_[e].desiredDistance)) return false;
  }
  return true;
}

bool Formation::isCongruent(const Positions& q, const Velocities& v, double tolerance,
                            double maxSpeed) const {
  // Speeds first, O(n): the O(n^2) pair test runs only once every agent is slow.
  return allSlowerThan(v, maxSpeed) && congruenceSlack(q, tolerance) >= 0.0;
}

bool CongruenceTracker::check(const Formation& formation, const Positions& q, const Velocities& v, double scale) {
  if (!formation.allSlowerThan(v, maxSpeed_)) return false;
  const Eigen::VectorXd centroid = q.rowwise().mean();
  if (anchored_ && scale == anchorScale_) {
    // A pair distance does not change when both ends move by the same vector: measure each
    // agent's displacement after moving the anchor by the change of the centroid.
    const Eigen::VectorXd shift = centroid - anchorCentroid_;
    double first = 0.0, second = 0.0;  // the two largest displacements from the shifted anchor
    for (int i = 0; i < formation.agentCount(); ++i) {
      const double d = (q.col(i) - anchor_.col(i) - shift).norm();
      if (d > first) {
        second = first;
        first = d;
      } else if (d > second) {
        second = d;
      }
    }
    if (first + second <= 0.5 * slack_) return true;
  }
  ++fullTests_;
  anchored_ = false;
  const double slack = formation.congruenceSlack(q, tolerance_, scale);
  if (!(slack >= 0.0)) return false;
  // A slack at the level of rounding (relative to the coordinates) certifies nothing: keep
  // testing in full then.
  if (std::isfinite(slack) && slack > 1e-9 * q.cwiseAbs().maxCoeff()) {
    anchored_ = true;
    anchor_ = q;
    anchorCentroid_ = centroid;
    anchorScale_ = scale;
    slack_ = slack;
  }
  return true;
}

}  // namespace vf
