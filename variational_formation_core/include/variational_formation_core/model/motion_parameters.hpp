#pragma once

#include <string>
#include <vector>

#include "variational_formation_core/model/formation.hpp"

namespace vf {

/**
 * Agent i's motion parameters (doc/maths.md §9): weights mu_ij over its neighbours, computed once
 * from the desired shape q*, with sum_j mu_ij (q*_i - q*_j) = q*_i - c* (c* the centroid of q*).
 * The relation is linear, so on every scaled, rotated, translated copy q = s R q* + t of the shape
 * sum_j mu_ij (q_i - q_j) = q_i - c: the agent knows its offset from the centroid from its
 * neighbours' positions alone. When the equation has many solutions (more neighbours than d) the
 * one of minimum norm is taken.
 */
struct MotionParameters {
  /// mu_ij in the order of Formation::neighbours(i) [1].
  std::vector<double> weights;
  /// Whether q*_i - c* is reached: false if the edge vectors at i do not span it (typically
  /// fewer than d independent edge vectors); then weights are the least-squares ones.
  bool exact = false;
  /// One line saying why the agent does not qualify (empty if it does).
  std::string problem;
};

/**
 * Agent i's motion parameters, from the desired shape only. Every path (centralised or one
 * agent of a distributed run) calls this same function, so the weights agree bit for bit.
 */
MotionParameters motionParameters(const Formation& formation, int agent);

/**
 * r_i = sum_j mu_ij (q_i - q_j) [m, world frame]: agent i's offset from the centroid on a
 * congruent shape. Reads only column i and the neighbours' columns of q.
 * @param out d doubles.
 */
void centroidOffset(const Formation& formation, const MotionParameters& parameters, int agent,
                    const Positions& q, double* out);

/// centroidOffset with q_i at `qi` and q_j at column(j) (d doubles each, j in N_i): the same
/// operations in the same order, without a d x n matrix.
template <class Column>
void centroidOffsetFrom(const Formation& formation, const MotionParameters& parameters, int agent, const double* qi,
                        Column column, double* out) {
  const int d = formation.dimension();
  for (int a = 0; a < d; ++a) out[a] = 0.0;
  const std::vector<Neighbour>& nbs = formation.neighbours(agent);
  for (std::size_t e = 0; e < nbs.size(); ++e) {
    const double* qj = column(nbs[e].agent);
    const double mu = parameters.weights[e];
    for (int a = 0; a < d; ++a) out[a] += mu * (qi[a] - qj[a]);
  }
}

}  // namespace vf
