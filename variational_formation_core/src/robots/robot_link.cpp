#include "variational_formation_core/robots/robot_link.hpp"

#include <cmath>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"

namespace vf {

RobotKinematics parseKinematics(const std::string& word) {
  if (word == "holonomic") return RobotKinematics::Holonomic;
  if (word == "unicycle") return RobotKinematics::Unicycle;
  throw InvalidInput("kinematics: expected holonomic or unicycle, got '" + word + "'");
}

RobotFeedback parseFeedback(const std::string& word) {
  if (word == "integrated") return RobotFeedback::Integrated;
  if (word == "odometry") return RobotFeedback::Odometry;
  throw InvalidInput("feedback: expected integrated or odometry, got '" + word + "'");
}

const char* kinematicsName(RobotKinematics kinematics) {
  return kinematics == RobotKinematics::Unicycle ? "unicycle" : "holonomic";
}

const char* feedbackName(RobotFeedback feedback) {
  return feedback == RobotFeedback::Odometry ? "odometry" : "integrated";
}

RobotLink::RobotLink(const RobotLinkSettings& settings, int dimension, double timeStep)
    : settings_(settings), dimension_(dimension), timeStep_(timeStep) {
  if (dimension != 2 && dimension != 3) {
    throw InvalidInput("dimension: expected 2 or 3, got " + std::to_string(dimension));
  }
  requireFiniteAbove("time_step", timeStep, 0.0, "s");
  requireFiniteAtLeast("robot_lag", settings.lag, 0.0, "s");
  requireFiniteAtLeast("correction_time", settings.correctionTime, 0.0, "s");
  if (!std::isfinite(settings.trackingGain)) {
    throw InvalidInput("tracking_gain: must be finite (< 0 for the default 1 / (4 (robot_lag + h))), got " +
                       formatNumber(settings.trackingGain));
  }
  if (settings.kinematics == RobotKinematics::Unicycle) {
    validateHandPoint(settings.hand);
    if (dimension != 2) {
      throw InvalidInput("kinematics: unicycle robots drive on the plane; the scenario is " +
                         std::to_string(dimension) + "D");
    }
  }
  trackingGain_ = settings.trackingGain >= 0.0 ? settings.trackingGain : 1.0 / (4.0 * (settings.lag + timeStep));
  point_.assign(static_cast<std::size_t>(dimension), 0.0);
}

PlanarPose pointFromOdometry(RobotKinematics kinematics, double handOffset, int dimension, double x, double y,
                             double z, double qx, double qy, double qz, double qw, double* point) {
  // poseFromOdometry checks every number and the quaternion, for either kinematics.
  const PlanarPose pose = poseFromOdometry(x, y, qx, qy, qz, qw);
  if (dimension == 3 && !std::isfinite(z)) {
    throw InvalidInput("odometry: position and orientation must be finite, got z " + formatNumber(z));
  }
  if (kinematics == RobotKinematics::Unicycle) {
    handPoint(pose, handOffset, point);
  } else {
    point[0] = x;
    point[1] = y;
    if (dimension == 3) point[2] = z;
  }
  return pose;
}

void RobotLink::measureOdometry(double x, double y, double z, double qx, double qy, double qz, double qw) {
  const PlanarPose pose =
      pointFromOdometry(settings_.kinematics, settings_.hand.handOffset, dimension_, x, y, z, qx, qy, qz, qw,
                        point_.data());
  if (settings_.kinematics == RobotKinematics::Unicycle) heading_ = pose.heading;
  measured_ = true;
}

void RobotLink::measurePose(const PlanarPose& pose) {
  handPoint(pose, settings_.hand.handOffset, point_.data());
  heading_ = pose.heading;
  measured_ = true;
}

void RobotLink::measurePoint(const std::vector<double>& point) {
  if (point.size() != point_.size()) {
    throw InvalidInput("measured position: expected " + std::to_string(point_.size()) + " values, got " +
                       std::to_string(point.size()));
  }
  point_ = point;
  measured_ = true;
}

void RobotLink::startPosition(const std::vector<double>& integrated, std::vector<double>& out) const {
  if (!measured_) throw InvalidInput("robot: no odometry yet");
  if (settings_.feedback == RobotFeedback::Odometry) {
    out = point_;
  } else {
    correctedPosition(integrated, point_, timeStep_, settings_.correctionTime, out);
  }
}

RobotLink::Command RobotLink::command(const std::vector<double>& velocity, const std::vector<double>& target) {
  double u[3] = {0.0, 0.0, 0.0};
  for (std::size_t a = 0; a < point_.size(); ++a) {
    u[a] = velocity[a];
    // Track q_k, where the robot should be now, with the velocity as feed-forward.
    if (settings_.feedback == RobotFeedback::Integrated) u[a] += trackingGain_ * (target[a] - point_[a]);
  }
  Command c;
  ++commands_;
  if (settings_.kinematics == RobotKinematics::Holonomic) {
    for (int a = 0; a < 3; ++a) c.linear[a] = u[a];
    return c;
  }
  const UnicycleCommand w = handPointCommand(settings_.hand, heading_, u[0], u[1]);
  c.linear[0] = w.linear;
  c.angular = w.angular;
  c.saturated = w.saturated;
  if (c.saturated) ++saturated_;
  return c;
}

}  // namespace vf
