#pragma once

#include <vector>

#include "variational_formation_core/safety/safety_settings.hpp"

namespace vf {

/// One half-space a·δ >= b of the safe displacements (doc/maths.md §10), d <= 3 used entries.
struct HalfSpace {
  double normal[3] = {0.0, 0.0, 0.0};  ///< a [m]
  double bound = 0.0;                  ///< b [m^2]; b <= 0 keeps δ = 0 feasible
  /// Who states it: an agent id (>= 0), or obstacle k as -1 - k.
  int source = 0;
};

/**
 * The Euclidean projection of δ0 onto {δ : a_m·δ >= b_m for all m, |δ| <= ρ}, with its KKT
 * certificate: δ - δ0 = Σ λ_m a_m - μ δ, λ, μ >= 0, λ_m (a_m·δ - b_m) = 0, μ (|δ| - ρ) = 0.
 */
struct Projection {
  double delta[3] = {0.0, 0.0, 0.0};  ///< δ [m]
  /// false: no constraint binds and δ is δ0 itself, bit for bit.
  bool changed = false;
  /// false: no point satisfies every half-space (some b > 0: already closer than allowed); δ = 0.
  bool feasible = true;
  std::vector<double> multipliers;  ///< λ_m, one per half-space, 0 where inactive
  double speedMultiplier = 0.0;     ///< μ of the ball [1]
  std::vector<int> active;          ///< indices m of the binding half-spaces, ascending
  bool speedLimited = false;        ///< the ball binds
};

/**
 * The exact projection (doc/maths.md §10). In d <= 3 the solution lies on the affine set of at most
 * d independent binding half-spaces, possibly cut by the sphere |δ| = ρ; every such face's
 * nearest point to δ0 is a candidate, and the projection is the feasible candidate nearest to
 * δ0 (the first in a fixed order on ties). Half-spaces no δ with |δ| <= min(|δ0|, ρ) can touch
 * are left out first (the projection onto a convex set holding 0 is no longer than δ0), so only
 * the few near neighbours count. Afterwards δ is shrunk toward 0 if rounding left any a·δ < b,
 * so that a·δ >= b holds as computed. Deterministic: the same numbers in the same order give
 * the same δ everywhere. A non-finite δ0 (a diverging run) comes back untouched (changed false).
 * @param dimension d (2 or 3). @param delta0 δ0, d doubles [m].
 * @param maxStep ρ [m] (+inf: no ball).
 */
Projection projectDisplacement(int dimension, const double* delta0, const std::vector<HalfSpace>& constraints,
                               double maxStep);
/// The same into `out`, reusing its storage (no allocation per call once it has grown).
void projectDisplacement(int dimension, const double* delta0, const std::vector<HalfSpace>& constraints,
                         double maxStep, Projection& out);

/// Another agent as agent i senses it: its id and q_j^{k+1}.
struct SensedAgent {
  int id = 0;
  double position[3] = {0.0, 0.0, 0.0};  ///< [m]
  /// Widens r for this pair to r + margin [m] >= 0, and the sensing radius R to R + margin: where
  /// the position is old (timed and robot mode, doc/robots.md "Safety"). 0 in exact runs.
  double margin = 0.0;
  /// false: an agent of another formation (ForeignAgents), which does not state the pair's other
  /// half, so this agent takes the whole constraint, 2 z·δ >= -γ(|z|^2 - (r + m_j)^2) (doc/maths.md §10).
  bool reciprocates = true;
};

/**
 * Agent i's half-spaces at q = q_i^{k+1} (doc/maths.md §10), in this order: every sensed agent with
 * |z| < R + m_j, z = q - q_j, as 2 z·δ >= -(γ/2)(|z|^2 - (r + m_j)^2), m_j its margin (-γ(...) for one
 * that does not reciprocate), in the order given; then every obstacle k
 * with |w| < R, w = q - p_k, as 2 w·δ >= -γ(|w|^2 - (r/2)^2), in list order. Agents farther than R
 * may be passed (they are skipped), so a caller can pass every candidate of a grid's cells.
 * A gap already below r (by at most rounding, in a safe run) gives b = 0: no closer, and δ = 0
 * stays feasible.
 * @param sensed in ascending id (the order both agents of a pair and every run use).
 * @throws std::invalid_argument if the ids are not ascending.
 */
void safetyConstraints(const SafetySettings& settings, int dimension, const double* q,
                       const std::vector<SensedAgent>& sensed, const std::vector<Obstacle>& obstacles,
                       std::vector<HalfSpace>& out);

/// One agent's filtered step: the constraints it saw and their projection.
struct SafeStep {
  std::vector<HalfSpace> constraints;
  Projection projection;
};

/**
 * The safety filter of one agent's step (doc/maths.md §10): the projection of δ0 = q̂^{k+2} - q^{k+1}
 * onto safetyConstraints and |δ| <= maxSpeed h. The one implementation every run calls.
 * @param q q_i^{k+1}, @param delta0 δ0, d doubles each [m]. @param timeStep h [s].
 */
SafeStep filterDisplacement(const SafetySettings& settings, double timeStep, int dimension, const double* q,
                            const double* delta0, const std::vector<SensedAgent>& sensed,
                            const std::vector<Obstacle>& obstacles);
/// The same into `out`, reusing its storage.
void filterDisplacement(const SafetySettings& settings, double timeStep, int dimension, const double* q,
                        const double* delta0, const std::vector<SensedAgent>& sensed,
                        const std::vector<Obstacle>& obstacles, SafeStep& out);

/**
 * Filters one agent's next position in place: qNext = q + δ when a constraint binds, and is left
 * untouched (today's update, bit for bit) when none does, or when qNext - q is not finite (so that
 * a diverging run ends as diverged).
 * @param q q_i^{k+1}, @param qNext q̂_i^{k+2} in, q_i^{k+2} out; d doubles each [m].
 */
SafeStep filterNextPosition(const SafetySettings& settings, double timeStep, int dimension, const double* q,
                            double* qNext, const std::vector<SensedAgent>& sensed,
                            const std::vector<Obstacle>& obstacles);
/// The same into `out`, reusing its storage.
void filterNextPosition(const SafetySettings& settings, double timeStep, int dimension, const double* q,
                        double* qNext, const std::vector<SensedAgent>& sensed, const std::vector<Obstacle>& obstacles,
                        SafeStep& out);

}  // namespace vf
