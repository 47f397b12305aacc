#pragma once

#include "variational_formation_core/robots/unicycle_command.hpp"

namespace vf {

/**
 * Dead reckoning of a differential drive from its wheel angles, as a robot's own odometry does:
 * between two readings the wheels turned by dphi_l, dphi_r [rad], the axle travelled ds = r
 * (dphi_l + dphi_r) / 2 along an arc that turned it by dtheta = r (dphi_r - dphi_l) / track,
 * integrated at the mid-heading. It knows nothing of slip, drag or a wheel that sinks into the
 * floor, so it drifts from the true pose.
 */
class WheelOdometry {
 public:
  /// @param start the true pose to count from; radius, track [m] > 0.
  WheelOdometry(const PlanarPose& start, double wheelRadius, double track, double leftAngle, double rightAngle);
  /// The wheels' new angles [rad] (unwrapped joint positions).
  void update(double leftAngle, double rightAngle);
  /// The pose [m, m, rad], heading in (-pi, pi].
  PlanarPose pose() const;

 private:
  double radius_, track_;
  double x_, y_, heading_;
  double left_, right_;
};

}  // namespace vf
