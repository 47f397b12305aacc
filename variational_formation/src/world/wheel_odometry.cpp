#include "variational_formation/world/wheel_odometry.hpp"

#include <cmath>

namespace vf {

WheelOdometry::WheelOdometry(const PlanarPose& start, double wheelRadius, double track, double leftAngle,
                             double rightAngle)
    : radius_(wheelRadius), track_(track), x_(start.x), y_(start.y), heading_(start.heading),
      left_(leftAngle), right_(rightAngle) {}

void WheelOdometry::update(double leftAngle, double rightAngle) {
  const double dl = radius_ * (leftAngle - left_), dr = radius_ * (rightAngle - right_);
  left_ = leftAngle;
  right_ = rightAngle;
  const double ds = 0.5 * (dl + dr), dtheta = (dr - dl) / track_;
  const double mid = heading_ + 0.5 * dtheta;
  x_ += ds * std::cos(mid);
  y_ += ds * std::sin(mid);
  heading_ += dtheta;
}

PlanarPose WheelOdometry::pose() const { return {x_, y_, std::atan2(std::sin(heading_), std::cos(heading_))}; }

}  // namespace vf
