#pragma once

#include <cstdint>
#include <random>

#include "variational_formation_core/robots/unicycle_command.hpp"
#include "variational_formation_core/common/standard_normal.hpp"

namespace vf {

/// Limits and sensor of a simulated unicycle (differential-drive) robot.
struct UnicycleRobotSettings {
  double lag = 0.1;             ///< tau [s] >= 0 of the first-order lag on v and w (0: none)
  double maxSpeed = 2.0;        ///< [m/s] > 0; |v| commands are clamped to it
  double maxTurnRate = 4.0;     ///< [rad/s] > 0; |w| commands are clamped to it
  double odometryNoise = 0.01;  ///< standard deviation [m] >= 0 of each measured coordinate
  double headingNoise = 0.0;    ///< standard deviation [rad] >= 0 of the measured heading
};

/// lag >= 0, max_speed > 0, max_turn_rate > 0, odometry_noise >= 0, heading_noise >= 0, finite.
/// @throws InvalidInput naming the field (the robot_sim parameter names).
void validateUnicycleRobot(const UnicycleRobotSettings& settings);

/**
 * A planar unicycle (world frame, metres, radians) that tracks a commanded (v, w) = (linear.x,
 * angular.z) with a first-order lag tau on each:
 *
 *     v' = (u_v - v) / tau,  w' = (u_w - w) / tau,  x' = v cos theta,  y' = v sin theta,  theta' = w.
 *
 * For a constant command v(t) and theta(t) are solved exactly (theta = theta0 + u_w t + (w0 - u_w)
 * tau (1 - e^{-t/tau})). x and y are integrals of v cos theta and v sin theta, which have no closed
 * form; they are computed by 3-point Gauss-Legendre quadrature (order 6) on sub-intervals of at
 * most min(0.01 s, tau / 2). On each the integrand's scale of change is at least 1/(1/tau +
 * maxTurnRate), so the error is below 1e-7 m per second of motion at 2 m/s (doc/robots.md;
 * test_unicycle_robot compares with a fine RK4 reference and with the exact arc for tau = 0).
 *
 * A lateral command (linear.y) is ignored: a differential drive cannot move sideways.
 * Odometry: the true pose plus independent N(0, odometryNoise^2) on x and y and N(0,
 * headingNoise^2) on the heading, per measurement (seeded, core/random.hpp).
 */
class UnicycleRobot {
 public:
  /// @param initialPose axle pose [m, m, rad]. @throws InvalidInput on bad settings or a
  /// non-finite pose.
  UnicycleRobot(const UnicycleRobotSettings& settings, const PlanarPose& initialPose,
                std::uint64_t seed);

  /**
   * The command (cmd_vel linear.x [m/s], linear.y [m/s], angular.z [rad/s]); v and w clamped to
   * their limits, `lateral` ignored. @throws InvalidInput on a non-finite value (the command is
   * then unchanged).
   */
  void setCommand(double linear, double lateral, double angular);
  /// Moves the robot on by dt [s] >= 0. @throws InvalidInput on a bad dt.
  void advance(double dt);
  /// A noisy pose measurement (draws noise); heading in (-pi, pi].
  PlanarPose measuredPose();

  /// The true axle pose; heading in (-pi, pi].
  PlanarPose pose() const;
  double linearVelocity() const { return v_; }
  double angularVelocity() const { return w_; }
  /// The command being tracked after clamping: (v, w).
  double commandedLinear() const { return uv_; }
  double commandedAngular() const { return uw_; }
  double time() const { return time_; }
  const UnicycleRobotSettings& settings() const { return settings_; }

 private:
  void advanceSubinterval(double dt);

  UnicycleRobotSettings settings_;
  double x_, y_, theta_;
  double v_ = 0.0, w_ = 0.0, uv_ = 0.0, uw_ = 0.0;
  double time_ = 0.0;
  std::mt19937_64 engine_;
  StandardNormal normal_;
};

}  // namespace vf
