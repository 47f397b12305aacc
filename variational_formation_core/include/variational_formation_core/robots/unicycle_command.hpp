#pragma once

#include <cstdint>

namespace vf {

/**
 * The near-identity (hand-point) transformation of a unicycle (doc/robots.md, "Unicycles"):
 * the point p = x + l (cos theta, sin theta), a hand offset l > 0 ahead of the wheel axle, moves
 * with
 *
 *     p' = [cos theta, -l sin theta; sin theta, l cos theta] (v, w),
 *
 * a matrix of determinant l != 0, so p can be given any planar velocity. The formation is run on
 * the hand points; the axle follows them at distance l.
 */
struct HandPointSettings {
  double handOffset = 0.1;   ///< l [m] > 0
  double maxSpeed = 2.0;     ///< [m/s] > 0, limit on |v| (cmd_vel linear.x)
  double maxTurnRate = 4.0;  ///< [rad/s] > 0, limit on |w| (cmd_vel angular.z)
};

/// hand_offset > 0, max_speed > 0, max_turn_rate > 0, all finite.
/// @throws InvalidInput naming the field (the parameter names).
void validateHandPoint(const HandPointSettings& settings);

/// A unicycle command (cmd_vel linear.x, angular.z).
struct UnicycleCommand {
  double linear = 0.0;    ///< v [m/s], along the heading
  double angular = 0.0;   ///< w [rad/s], counter-clockwise
  bool saturated = false; ///< the limits scaled the command down
};

/**
 * The command that gives the hand point the velocity (vx, vy) [m/s, world frame] at heading
 * theta [rad]: v = cos theta vx + sin theta vy, w = (-sin theta vx + cos theta vy) / l. If |v| or
 * |w| exceeds its limit, both are scaled by the same factor, so the hand point keeps the
 * direction of the commanded velocity and only its speed is reduced (saturated = true).
 * @throws InvalidInput on bad settings or a non-finite input.
 */
UnicycleCommand handPointCommand(const HandPointSettings& settings, double heading, double vx,
                                 double vy);

/// A planar pose: axle position [m] and heading [rad] in (-pi, pi], world frame.
struct PlanarPose {
  double x = 0.0;
  double y = 0.0;
  double heading = 0.0;
};

/// Largest accepted | |q| - 1 | of an odometry quaternion (the orientation must be a rotation).
constexpr double kQuaternionNormTolerance = 1e-3;

/**
 * The pose of an odometry message: position (x, y) [m] and the yaw of the quaternion
 * (qx, qy, qz, qw), atan2(2 (qw qz + qx qy), 1 - 2 (qy^2 + qz^2)). A tilt is ignored (the robot is
 * taken to drive on the plane).
 * @throws InvalidInput "odometry: ..." on a non-finite value or a quaternion whose norm is
 * farther than kQuaternionNormTolerance from 1.
 */
PlanarPose poseFromOdometry(double x, double y, double qx, double qy, double qz, double qw);

/// The hand point [m] of a pose: (x + l cos theta, y + l sin theta), written to p[0..1].
void handPoint(const PlanarPose& pose, double handOffset, double* p);

/// The axle pose whose hand point is p [m] at heading theta [rad].
PlanarPose axleFromHandPoint(const double* p, double heading, double handOffset);

/**
 * A seeded initial heading [rad] in [-pi, pi) for agent `id`: uniform, from std::mt19937_64
 * seeded with headingSeed and skipped by id draws, so each agent's heading depends only on
 * (headingSeed, id) and every node computes the same one.
 */
double drawInitialHeading(std::uint64_t headingSeed, int id);

}  // namespace vf
