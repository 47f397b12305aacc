#pragma once

#include <cmath>
#include <utility>
#include <vector>

#include "variational_formation_core/common/types.hpp"

namespace vf {

/// An undirected edge (i, j) of the sensing graph with its desired distance d_ij.
struct Edge {
  int tail;
  int head;
  double desiredDistance;
  double desiredDistanceSquared;
};

/// Agent j seen from agent i: the neighbour's index and d_ij^2.
struct Neighbour {
  int agent;
  double desiredDistanceSquared;
};

/**
 * Distance-based formation (paper Section 6.1): n agents in R^d, an undirected edge set E and
 * a desired shape q*. Desired distances are d_ij = |q*_i - q*_j|.
 *
 * Potential V(q) = 1/4 sum_{(i,j) in E} (|q_i - q_j|^2 - d_ij^2)^2 (paper eq. (eq: Vij)).
 */
class Formation {
 public:
  /**
   * @param dimension d, 2 or 3.
   * @param desiredShape d x n matrix of desired positions q*.
   * @param edges pairs (i, j) of distinct existing agents, no duplicates.
   * @throws InvalidInput if any of these is violated.
   */
  Formation(int dimension, Positions desiredShape, const std::vector<std::pair<int, int>>& edges);

  int dimension() const { return dimension_; }
  int agentCount() const { return static_cast<int>(desiredShape_.cols()); }
  const std::vector<Edge>& edges() const { return edges_; }
  /// N_i in the order the edges are listed; both update paths sum gradients in this order.
  const std::vector<Neighbour>& neighbours(int agent) const { return neighbours_[agent]; }
  const Positions& desiredShape() const { return desiredShape_; }

  /// V(q), doc/maths.md §1.
  double potential(const Positions& q) const;
  /// 1/2 sum_{j in N_i} V_ij(q): each edge's potential split half to each endpoint (of V_s with
  /// s^2 = scaleSquared under a commanded scale).
  double agentPotential(int agent, const Positions& q, double scaleSquared = 1.0) const;

  /**
   * grad_i V = sum_{j in N_i} (|q_i - q_j|^2 - d_ij^2)(q_i - q_j) (doc/maths.md §1; the paper's
   * Gamma_ij with its erratum fixed). Reads only column i and the columns of N_i, so the
   * agent node and the centralised run call this very function on the same numbers.
   * @param out d doubles.
   */
  void agentGradient(int agent, const Positions& q, double* out) const;
  /**
   * agentGradient with q_i at `qi` and q_j at column(j) (d doubles each, j in N_i): the very
   * operations in the same order, for an agent that holds only its neighbours' positions (a
   * d x n matrix per agent would make a formation's memory grow as n^2).
   */
  template <class Column>
  void agentGradientFrom(int agent, const double* qi, Column column, double* out) const {
    agentScaledGradientFrom(agent, qi, column, 1.0, out);  // 1.0 * d_ij^2 is d_ij^2 exactly
  }
  /**
   * grad_i V_s for the scaled distances s d_ij (doc/maths.md §9): gamma_ij = |q_i - q_j|^2 - s^2 d_ij^2.
   * @param scaleSquared s^2 [1]. Same reads and order as agentGradient.
   */
  void agentScaledGradient(int agent, const Positions& q, double scaleSquared, double* out) const;
  /// agentScaledGradient with q_i at `qi` and q_j at column(j), as agentGradientFrom.
  template <class Column>
  void agentScaledGradientFrom(int agent, const double* qi, Column column, double scaleSquared, double* out) const {
    for (int c = 0; c < dimension_; ++c) out[c] = 0.0;
    for (const Neighbour& nb : neighbours_[agent]) {
      const double* qj = column(nb.agent);
      const double gamma = squaredDistance(qi, qj, dimension_) - scaleSquared * nb.desiredDistanceSquared;
      for (int c = 0; c < dimension_; ++c) out[c] += gamma * (qi[c] - qj[c]);
    }
  }
  /// |a - b|^2 of d coordinates, coordinate by coordinate, so that every caller sums in the same
  /// order whatever the memory alignment.
  static double squaredDistance(const double* a, const double* b, int d) {
    double s = 0.0;
    for (int c = 0; c < d; ++c) {
      const double diff = a[c] - b[c];
      s += diff * diff;
    }
    return s;
  }
  /// V_s(q) for the scaled distances s d_ij, @param scaleSquared s^2.
  double scaledPotential(const Positions& q, double scaleSquared) const;
  /// Stacked gradient, d x n, agent by agent through agentGradient.
  void gradient(const Positions& q, Gradients& out) const;
  /// Hessian of V, (dn) x (dn), with agent i in rows/columns [d i, d i + d).
  Eigen::MatrixXd hessian(const Positions& q) const;

  /// Rigidity matrix R(q), |E| x dn: row (i,j) holds (q_i - q_j)^T at i and -(q_i - q_j)^T at j.
  Eigen::MatrixXd rigidityMatrix(const Positions& q) const;
  /// Numerical rank of R(q).
  int rigidityRank(const Positions& q) const;
  /// rank R = dn - d(d+1)/2 (2n-3 in 2D, 3n-6 in 3D), for n >= d + 1.
  bool isInfinitesimallyRigid(const Positions& q) const;
  /// Infinitesimally rigid and |E| = dn - d(d+1)/2.
  bool isMinimallyRigid(const Positions& q) const;

  /// Per edge |q_i - q_j| - s d_ij, in the order of edges(); s is a commanded scale (doc/maths.md §9).
  Eigen::VectorXd distanceErrors(const Positions& q, double scale = 1.0) const;
  /// max_e |distance error_e| against s d_ij, 0 without edges.
  double maxDistanceError(const Positions& q, double scale = 1.0) const;

  /**
   * Congruence (paper Section 6.2): every pairwise distance, over all pairs, is within
   * tolerance (relative) of the desired shape's and every agent's speed is below maxSpeed.
   */
  bool isCongruent(const Positions& q, const Velocities& v, double tolerance = 0.01,
                   double maxSpeed = 0.1) const;
  /// Every agent's speed is below maxSpeed (isCongruent's speed part).
  bool allSlowerThan(const Velocities& v, double maxSpeed) const;
  /// isCongruent's pair part: min over all pairs of tolerance D_ij - |a_ij - D_ij| with D_ij = s d_ij,
  /// s a commanded scale (>= 0 iff every pair is within tolerance; +inf with fewer than two agents).
  /// It stops at the first pair outside, and returns that pair's negative (or NaN) value.
  double congruenceSlack(const Positions& q, double tolerance, double scale = 1.0) const;
  /// Shape error: max over all pairs, not only the edges, of | |q_i - q_j| - s |q*_i - q*_j| | [m]
  /// (0 with fewer than two agents). A folded realization with every edge right has a large
  /// one; a mirror image has none (doc/scenarios.md, "Mirror images"). O(n^2).
  double shapeError(const Positions& q, double scale = 1.0) const;
  /// Every edge within `tolerance` (relative) of s d_ij: the edge part of congruence.
  bool edgesWithin(const Positions& q, double tolerance, double scale = 1.0) const;

 private:
  /// | |q_i - q_j| - desired | with desired = s |q*_i - q*_j| [m]: the one pair comparison of
  /// congruenceSlack and shapeError.
  double pairError(const Positions& q, int i, int j, double scale, double& desired) const {
    desired = scale * (desiredShape_.col(i) - desiredShape_.col(j)).norm();
    return std::abs((q.col(i) - q.col(j)).norm() - desired);
  }

  int dimension_;
  Positions desiredShape_;
  std::vector<Edge> edges_;
  std::vector<std::vector<Neighbour>> neighbours_;
};

/**
 * Formation::isCongruent for a sequence of configurations (the monitor's steps) at an amortised
 * O(n) per call instead of O(n^2) once the formation holds its shape. Always the same answer as
 * isCongruent: after a full pair test that passes, it keeps the configuration (the anchor) and
 * the smallest slack s = min over pairs of (tol d_ij - |a_ij - d_ij|). A pair distance moves by
 * at most D_i + D_j, the agents' displacements from the anchor (triangle inequality), so while
 * the two largest displacements sum to at most s/2 every pair still passes, with s/2 to spare
 * for rounding; otherwise it runs the full test again.
 */
class CongruenceTracker {
 public:
  CongruenceTracker(double tolerance, double maxSpeed) : tolerance_(tolerance), maxSpeed_(maxSpeed) {}
  /**
   * formation.isCongruent(q, v, tolerance, maxSpeed) for one formation throughout, with the pairs
   * measured against s d_ij (s = `scale`). Under a commanded motion `v` is the velocity relative
   * to it (FormationMonitor). Displacements from the anchor are taken after moving the anchor's
   * centroid onto q's, so a translating formation stays anchored; a new scale tests in full.
   */
  bool check(const Formation& formation, const Positions& q, const Velocities& v, double scale = 1.0);
  /// How many full O(n^2) pair tests check() ran.
  long fullTests() const { return fullTests_; }

 private:
  double tolerance_, maxSpeed_;
  bool anchored_ = false;
  Positions anchor_;
  Eigen::VectorXd anchorCentroid_;
  double anchorScale_ = 1.0;
  double slack_ = 0.0;
  long fullTests_ = 0;
};

/// The number dn - d(d+1)/2 of independent edges a rigid framework of n >= d+1 agents needs.
int rigidEdgeCount(int dimension, int agentCount);

}  // namespace vf
