#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "variational_formation_core/common/standard_normal.hpp"

namespace vf {

/// Limits and sensor of a simulated holonomic point robot.
struct PointRobotSettings {
  double lag = 0.1;              ///< tau [s] >= 0 of the first-order velocity lag (0: none)
  double maxSpeed = 2.0;         ///< [m/s] > 0; commands are clamped to it
  double maxAcceleration = 20.0; ///< [m/s^2] > 0
  double odometryNoise = 0.01;   ///< standard deviation [m] >= 0 of each measured coordinate
};

/// lag >= 0, max_speed > 0, max_acceleration > 0, odometry_noise >= 0, all finite.
/// @throws InvalidInput naming the field (the robot_sim parameter names).
void validatePointRobot(const PointRobotSettings& settings);

/**
 * A holonomic point robot in 2D or 3D (world frame, metres) that tracks a commanded velocity u:
 *
 *     v' = sat((u - v) / tau, maxAcceleration),   p' = v,   |u| <= maxSpeed (clamped),
 *
 * where sat limits the norm. v moves along the straight line towards u, so the motion is one
 * dimensional in |u - v| and is integrated EXACTLY over any interval (no integration error, the
 * result does not depend on how a time is split into steps): while |u - v| > maxAcceleration tau
 * it falls linearly at maxAcceleration, after that it decays as e^{-t/tau}. Since v stays on the
 * segment from its start to u, |v| <= maxSpeed once it starts there.
 *
 * Odometry: the true position plus independent N(0, odometryNoise^2) per coordinate per
 * measurement (seeded, core/random.hpp), white noise without drift.
 */
class PointRobot {
 public:
  /// @throws InvalidInput on bad settings or a position that is not 2 or 3 finite numbers.
  PointRobot(const PointRobotSettings& settings, const std::vector<double>& initialPosition,
             std::uint64_t seed);

  /// Commanded velocity [m/s], clamped to maxSpeed (norm). @throws InvalidInput on a wrong size or
  /// non-finite value (the command is then unchanged).
  void setCommand(const std::vector<double>& velocity);
  /// Moves the robot on by dt [s] >= 0 exactly. @throws InvalidInput on a bad dt.
  void advance(double dt);
  /// A noisy position measurement [m] (draws noise).
  std::vector<double> measuredPosition();

  int dimension() const { return static_cast<int>(p_.size()); }
  const std::vector<double>& position() const { return p_; }
  const std::vector<double>& velocity() const { return v_; }
  /// The command being tracked, after clamping [m/s].
  const std::vector<double>& command() const { return u_; }
  /// Time advanced so far [s].
  double time() const { return time_; }
  const PointRobotSettings& settings() const { return settings_; }

 private:
  PointRobotSettings settings_;
  std::vector<double> p_, v_, u_;
  double time_ = 0.0;
  std::mt19937_64 engine_;
  StandardNormal normal_;
};

}  // namespace vf
