#include "variational_formation/ros/robot_sim_node.hpp"

#include <nav_msgs/Odometry.h>

#include "variational_formation/core/error.hpp"
#include "variational_formation/core/number_checks.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/participants.hpp"

namespace vf {

namespace {

/// The default ~frame_prefix: "/robots/r0" -> "robots/r0/", "/" -> "".
std::string namespacePrefix() {
  std::string ns = ros::this_node::getNamespace();
  while (!ns.empty() && ns.front() == '/') ns.erase(ns.begin());
  return ns.empty() ? ns : ns + "/";
}

}  // namespace

RobotSimNode::RobotSimNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  const int id = requiredParam<int>(pnh, "id");
  if (id < 0) throw InvalidInput("~id: must be >= 0, got " + std::to_string(id));
  const std::vector<double> initial = requiredParam<std::vector<double>>(pnh, "initial_position");
  const double rate = optionalParam(pnh, "rate", 100.0);
  PointRobotSettings settings;
  settings.lag = optionalParam(pnh, "lag", settings.lag);
  settings.maxSpeed = optionalParam(pnh, "max_speed", settings.maxSpeed);
  settings.maxAcceleration = optionalParam(pnh, "max_acceleration", settings.maxAcceleration);
  settings.odometryNoise = optionalParam(pnh, "odometry_noise", settings.odometryNoise);
  const int seed = optionalParam(pnh, "seed", id);
  cmdTimeout_ = optionalParam(pnh, "cmd_timeout", cmdTimeout_);
  const std::string prefix = optionalParam(pnh, "frame_prefix", namespacePrefix());
  try {
    requireFiniteAbove("rate", rate, 0.0, "Hz");
    requireFiniteAtLeast("seed", seed, 0.0, "");
    requireFiniteAtLeast("cmd_timeout", cmdTimeout_, 0.0, "s");
    robot_ = std::make_unique<PointRobot>(settings, initial, static_cast<std::uint64_t>(seed));
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string("~") + e.what());  // the core names the parameter without '~'
  }
  childFrame_ = prefix + "robot_" + std::to_string(id) + "/base_link";
  odomPub_ = nh.advertise<nav_msgs::Odometry>("odom", 100);
  commandSub_ = nh.subscribe("cmd_vel", 100, &RobotSimNode::onCommand, this, ros::TransportHints().tcpNoDelay());
  timer_ = nh.createTimer(ros::Duration(1.0 / rate), &RobotSimNode::onTimer, this);
  ROS_INFO("%s: robot %d (%s) at %s%s, %g Hz, lag %g s, max speed %g m/s, max acceleration %g m/s^2, "
           "odometry noise %g m, seed %d, cmd_vel timeout %g s",
           ros::this_node::getName().c_str(), id, childFrame_.c_str(), formatNumber(initial[0]).c_str(),
           (", " + formatNumber(initial[1]) + (initial.size() > 2 ? ", " + formatNumber(initial[2]) : "")).c_str(),
           rate, settings.lag, settings.maxSpeed, settings.maxAcceleration, settings.odometryNoise, seed,
           cmdTimeout_);
}

void RobotSimNode::run() { ros::spin(); }

void RobotSimNode::onCommand(const geometry_msgs::Twist::ConstPtr& msg) {
  std::vector<double> u{msg->linear.x, msg->linear.y, msg->linear.z};
  u.resize(static_cast<std::size_t>(robot_->dimension()));  // planar robots ignore z
  try {
    robot_->setCommand(u);
    lastCommand_ = ros::Time::now();
    stopped_ = false;
  } catch (const InvalidInput& e) {
    ++malformed_;
    ROS_WARN_THROTTLE(1.0, "%s: dropped a cmd_vel: %s; %ld dropped so far", ros::this_node::getName().c_str(),
                      e.what(), malformed_);
  }
}

void RobotSimNode::onTimer(const ros::TimerEvent& event) {
  const ros::Time now = event.current_real;
  if (!stopped_ && cmdTimeout_ > 0.0 && (now - lastCommand_).toSec() > cmdTimeout_) {
    robot_->setCommand(std::vector<double>(static_cast<std::size_t>(robot_->dimension()), 0.0));
    stopped_ = true;
    ROS_WARN("%s: no cmd_vel for %g s: stopping", ros::this_node::getName().c_str(), cmdTimeout_);
  }
  // The robot model is exact for any interval: advance by the time that really passed.
  if (!lastTick_.isZero() && now > lastTick_) robot_->advance((now - lastTick_).toSec());
  lastTick_ = now;
  publish(now);
}

void RobotSimNode::publish(const ros::Time& stamp) {
  const std::vector<double>& p = robot_->position();
  const std::vector<double>& v = robot_->velocity();
  const std::vector<double> measured = robot_->measuredPosition();
  const bool planar = robot_->dimension() == 2;
  nav_msgs::Odometry odom;
  odom.header.stamp = stamp;
  odom.header.frame_id = "world";
  odom.child_frame_id = childFrame_;
  odom.pose.pose.position.x = measured[0];
  odom.pose.pose.position.y = measured[1];
  odom.pose.pose.position.z = planar ? 0.0 : measured[2];
  odom.pose.pose.orientation.w = 1.0;  // a point robot: base_link keeps the world's axes
  const double variance = robot_->settings().odometryNoise * robot_->settings().odometryNoise;
  odom.pose.covariance[0] = variance;
  odom.pose.covariance[7] = variance;
  odom.pose.covariance[14] = planar ? 0.0 : variance;
  odom.twist.twist.linear.x = v[0];  // base_link and world axes agree
  odom.twist.twist.linear.y = v[1];
  odom.twist.twist.linear.z = planar ? 0.0 : v[2];
  odomPub_.publish(odom);

  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = "world";
  tf_.sendTransform(frameAt(header, childFrame_, {p[0], p[1], planar ? 0.0 : p[2]}));
}

}  // namespace vf
