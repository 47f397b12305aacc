#include "variational_formation_core/robots/unicycle_command.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/common/standard_normal.hpp"

namespace vf {

namespace {
constexpr double kPi = 3.141592653589793;
}

void validateHandPoint(const HandPointSettings& settings) {
  requireFiniteAbove("hand_offset", settings.handOffset, 0.0, "m");
  requireFiniteAbove("max_speed", settings.maxSpeed, 0.0, "m/s");
  requireFiniteAbove("max_turn_rate", settings.maxTurnRate, 0.0, "rad/s");
}

UnicycleCommand handPointCommand(const HandPointSettings& settings, double heading, double vx,
                                 double vy) {
  validateHandPoint(settings);
  if (!std::isfinite(heading) || !std::isfinite(vx) || !std::isfinite(vy)) {
    throw InvalidInput("hand-point command: heading and velocity must be finite, got heading " +
                       formatNumber(heading) + ", velocity (" + formatNumber(vx) + ", " +
                       formatNumber(vy) + ")");
  }
  // The inverse of p' = [c, -l s; s, l c] (v, w): doc/robots.md, "Unicycles".
  const double c = std::cos(heading);
  const double s = std::sin(heading);
  UnicycleCommand command;
  command.linear = c * vx + s * vy;
  command.angular = (-s * vx + c * vy) / settings.handOffset;
  const double scale = std::min({1.0, settings.maxSpeed / std::abs(command.linear),
                                  settings.maxTurnRate / std::abs(command.angular)});
  if (scale < 1.0) {
    command.linear *= scale;
    command.angular *= scale;
    command.saturated = true;
  }
  return command;
}

PlanarPose poseFromOdometry(double x, double y, double qx, double qy, double qz, double qw) {
  for (double value : {x, y, qx, qy, qz, qw}) {
    if (!std::isfinite(value)) {
      throw InvalidInput("odometry: position and orientation must be finite, got position (" +
                         formatNumber(x) + ", " + formatNumber(y) + "), quaternion (" + formatNumber(qx) +
                         ", " + formatNumber(qy) + ", " + formatNumber(qz) + ", " + formatNumber(qw) + ")");
    }
  }
  const double norm = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
  if (!(std::abs(norm - 1.0) <= kQuaternionNormTolerance)) {
    throw InvalidInput("odometry: the orientation quaternion must have norm 1 (within " +
                       formatNumber(kQuaternionNormTolerance) + "), got norm " + formatNumber(norm));
  }
  PlanarPose pose;
  pose.x = x;
  pose.y = y;
  pose.heading = std::atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz));
  return pose;
}

void handPoint(const PlanarPose& pose, double handOffset, double* p) {
  p[0] = pose.x + handOffset * std::cos(pose.heading);
  p[1] = pose.y + handOffset * std::sin(pose.heading);
}

PlanarPose axleFromHandPoint(const double* p, double heading, double handOffset) {
  PlanarPose pose;
  pose.x = p[0] - handOffset * std::cos(heading);
  pose.y = p[1] - handOffset * std::sin(heading);
  pose.heading = heading;
  return pose;
}

double drawInitialHeading(std::uint64_t headingSeed, int id) {
  if (id < 0) throw InvalidInput("id: must be >= 0, got " + std::to_string(id));
  std::mt19937_64 engine(headingSeed);
  engine.discard(static_cast<unsigned long long>(id));
  return -kPi + 2.0 * kPi * uniformUnit(engine);
}

}  // namespace vf
