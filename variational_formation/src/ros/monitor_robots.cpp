// The robots of a robot-mode run as the monitor sees them (MonitorNode, monitor_node.hpp;
// doc/robots.md, "Converged means the robots"): with ~measure_robots it reads every robot's
// odometry, measures the robots' shape at each status (core RobotShapeWatch: averaged odometry,
// hand points for unicycles, the agents' errors and tolerance), and the run converges only once
// the robots are in shape too (robotModeOutcome).
#include <limits>
#include <sstream>

#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/common/yaml_text.hpp"
#include "variational_formation_core/robots/robot_link.hpp"
#include "variational_formation/ros/monitor_node.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/liveness.hpp"

namespace vf {

namespace {
constexpr double kMissingReportEvery = 5.0;  // [s] between lines about robots without odometry
}  // namespace

void MonitorNode::setUpRobots(ros::NodeHandle& nh, ros::NodeHandle& pnh, bool timed) {
  if (!optionalParam(pnh, "measure_robots", false)) return;
  if (!timed) throw InvalidInput("~measure_robots: robots are driven by timed agents; lockstep mode has none");
  RobotShapeSettings s;
  try {
    s.kinematics = parseKinematics(optionalParam<std::string>(pnh, "kinematics", kinematicsName(s.kinematics)));
    s.handOffset = optionalParam(pnh, "hand_offset", s.handOffset);
    s.window = optionalParam(pnh, "robots_window", s.window);
    robots_ = std::make_unique<RobotShapeWatch>(scenario_, s);
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string("~") + e.what());  // the core names the parameter without '~'
  }
  odomFrames_ = std::make_unique<FrameGate>(worldFrame_, "monitor", "that robot is not measured until odometry in '" +
                                                                         worldFrame_ + "' comes");
  for (int i = 0; i < scenario_.agentCount(); ++i) {
    odomSubs_.push_back(nh.subscribe<nav_msgs::Odometry>(
        "robot_" + std::to_string(i) + "/odom", 10,
        [this, i](const nav_msgs::Odometry::ConstPtr& msg) { onOdometry(i, *msg); }));
  }
  robotsReportedAt_ = ros::WallTime::now();  // the robots get 5 s to start before a line says they are missing
  const std::string hand =
      s.kinematics == RobotKinematics::Unicycle ? ", hand point " + formatNumber(s.handOffset) + " m ahead" : "";
  ROS_INFO("monitor: measures the robots (%s%s) from robot_<i>/odom averaged over %g s; the run converges once the "
           "robots are in shape too", kinematicsName(s.kinematics), hand.c_str(), s.window);
}

void MonitorNode::onOdometry(int id, const nav_msgs::Odometry& msg) {
  const auto& p = msg.pose.pose.position;
  const auto& o = msg.pose.pose.orientation;
  if (!odomFrames_->admit(msg.header.frame_id, odomSubs_[static_cast<std::size_t>(id)].getTopic())) return;
  try {
    robots_->addOdometry(id, ros::WallTime::now().toSec(), p.x, p.y, p.z, o.x, o.y, o.z, o.w);
  } catch (const InvalidInput& e) {
    ++badOdometry_;
    ROS_WARN_THROTTLE(1.0, "monitor: dropped an odometry message on %s: %s; %ld dropped so far",
                      odomSubs_[static_cast<std::size_t>(id)].getTopic().c_str(), e.what(), badOdometry_);
  }
}

void MonitorNode::watchRobots(const FormationSnapshot& s, FormationStatus& status) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  status.robots_in_shape = false;
  status.robots_in_shape_step = -1;
  status.robots_max_distance_error = status.robots_shape_error = nan;
  if (!robots_) return;
  const RobotShapeStep& r = robots_->observe(s.metrics.step, ros::WallTime::now().toSec(), s.scale);
  status.robots_in_shape = r.inShapeSince >= 0;
  status.robots_in_shape_step = r.inShapeSince;
  status.robots_max_distance_error = r.findings.maxEdgeError;
  status.robots_shape_error = r.findings.shapeError;
  if (r.inShapeSince >= 0 && reportedRobots_ != r.inShapeSince) {
    ROS_INFO("monitor: the robots (odometry) in %s since step %ld (t = %.3f s)",
             r.findings.mirrored && !scenario_.mirrorAllowed ? "the mirror image of the desired shape" : "the desired shape",
             r.inShapeSince, r.inShapeSince * scenario_.timeStep);
    reportedRobots_ = r.inShapeSince;
  } else if (r.inShapeSince < 0 && reportedRobots_ >= 0) {
    const std::string why = r.measured ? "max distance error " + formatRounded(r.findings.maxEdgeError) + " m"
                                       : r.unmeasured;
    ROS_INFO("monitor: the robots left the desired shape at step %ld (%s)", s.metrics.step, why.c_str());
    reportedRobots_ = -2;
  }
}

void MonitorNode::reportRobotsMissing() {
  if (!robots_ || secondsSince(robotsReportedAt_) < kMissingReportEvery) return;
  const double now = ros::WallTime::now().toSec();
  std::vector<int> missing = robots_->unheard();
  const char* what = "no odometry yet";
  if (missing.empty()) {
    missing = robots_->silent(now);
    what = "odometry stopped";
  }
  if (missing.empty()) return;
  std::string topics;
  for (int i : missing) topics += (topics.empty() ? "" : ", ") + odomSubs_[static_cast<std::size_t>(i)].getTopic();
  ROS_WARN("monitor: waiting for the robots' odometry: %s on %s%s; the robots are not measured (not in shape) until "
           "every one is heard", what, topics.c_str(), odomFrames_->refusedNote().c_str());
  robotsReportedAt_ = ros::WallTime::now();
}

std::string MonitorNode::robotsResultLines() const {
  if (!robots_) return "";
  const ShapeOutcome robots = robots_->outcome(scenario_.timeStep);
  const ShapeOutcome agents = agentsVerdict();
  std::ostringstream out;
  out << "robots_in_shape_step: " << robots.convergedStep << "\nrobots_max_distance_error: "
      << robots.findings.maxEdgeError << "\nrobots_shape_error: " << robots.findings.shapeError
      << "\nrobots: " << yamlQuoted(robots.line) << "\nagents_converged_step: " << agents.convergedStep
      << "\nodometry_dropped: " << badOdometry_ << "\nodometry_refused_frame: " << odomFrames_->refused() << "\n";
  return out.str();
}

}  // namespace vf
