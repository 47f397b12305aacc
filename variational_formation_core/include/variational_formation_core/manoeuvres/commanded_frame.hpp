#pragma once

#include "variational_formation_core/model/formation.hpp"
#include "variational_formation_core/manoeuvres/command_schedule.hpp"

namespace vf {

/**
 * How well a formation follows a command (doc/manoeuvres.md, metrics.csv): measured from
 * positions and velocities only, with no knowledge of the command but the scale.
 */

/// The centroid's velocity, the mean of the agents' velocities [m/s, world frame] (z = 0 in 2D).
Vector3 centroidVelocity(const Velocities& v);

/**
 * The formation's rotation rate [rad/s, world frame; in 2D only z]: the rotation that best maps
 * the centred configuration q - h v onto the centred q (least squares; Kabsch in 3D), as an
 * angle per h about its axis. For the variational scheme, whose v is (q_k - q_{k-1})/h, that is
 * the rotation of the last step: exact for a rigid discrete rotation. 0 with fewer than 2 agents.
 */
Vector3 rotationRate(const Positions& q, const Velocities& v, double timeStep);

/// Mean over edges of |q_i - q_j| / d_ij, minus s [1]: 0 when every edge has length s d_ij,
/// negative while the formation is smaller than commanded. 0 without edges.
double meanScaleError(const Formation& formation, const Positions& q, double scale);

/// max over edges of | |q_i - q_j| - s d_ij | [m]: Formation::maxDistanceError(q, s).
inline double maxScaledDistanceError(const Formation& formation, const Positions& q, double scale) {
  return formation.maxDistanceError(q, scale);
}

/// v_i -= v* + omega* x (q_i - c), c the centroid of q: the velocities in the frame the command
/// moves [m/s] (untouched when the command does not move the formation).
void subtractCommandedMotion(const Command& command, const Positions& q, Velocities& v);

/// Where a commanded motion has taken the desired shape by step k (the monitor's ghost).
struct CommandedFrame {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  ///< exp(omega*_j h) over intervals j < k, in order
  double scale = 1.0;                                       ///< s of interval k
  Vector3 velocity = Vector3::Zero();                       ///< v* of interval k [m/s]
};

/// The commanded frame at step k >= 0 of `schedule` at time step h [s]; O(number of entries).
CommandedFrame commandedFrame(const CommandSchedule& schedule, long step, double timeStep);

}  // namespace vf
