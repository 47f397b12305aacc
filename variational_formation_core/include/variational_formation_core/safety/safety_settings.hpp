#pragma once

#include <limits>

#include "variational_formation_core/common/types.hpp"

namespace vf {

/// The scenario's optional `safety:` block (doc/scenarios.md, doc/maths.md §10).
struct SafetySettings {
  double radius = 0.0;         ///< r [m]: no two agents' centres come closer than this
  double sensingRadius = 0.0;  ///< R [m] > r: agents and obstacles nearer than this are sensed
  double gamma = 0.0;          ///< γ in (0, 1]: how fast a pair may approach r (1 = in one step)
  /// |δ| <= maxSpeed h per step [m/s]; +inf = no limit (the field is optional).
  double maxSpeed = std::numeric_limits<double>::infinity();
  /// A run is blocked once the filter binds and the distance error has not fallen for this long [s].
  double blockedAfter = 10.0;
};

/// A convex obstacle of the scenario's `obstacles:` list: a disc (2D) or ball (3D), or an
/// axis-aligned box. Agents keep r/2 from it (the other half of r is the obstacle's side).
struct Obstacle {
  enum class Shape { Ball, Box };
  Shape shape = Shape::Ball;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< Ball [m] (z = 0 in 2D)
  double radius = 0.0;                               ///< Ball [m], >= 0
  Eigen::Vector3d min = Eigen::Vector3d::Zero();     ///< Box corner [m]
  Eigen::Vector3d max = Eigen::Vector3d::Zero();     ///< Box corner [m], >= min
};

/**
 * w = q - p, p the obstacle's nearest point to q (doc/maths.md §10): the gradient of
 * dist(q, C)^2 / 2. Zero inside the obstacle.
 * @param q d doubles [m]. @param w receives d doubles [m].
 */
void obstacleOffset(const Obstacle& obstacle, int dimension, const double* q, double* w);

}  // namespace vf
