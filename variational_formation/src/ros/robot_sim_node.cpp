#include "variational_formation/ros/robot_sim_node.hpp"

#include <cmath>

#include <nav_msgs/Odometry.h>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/frames.hpp"

namespace vf {

namespace {
/// The true pose on `ground_truth` (as a simulator's ground-truth odometry plugin publishes it).
void publishTruth(ros::Publisher& pub, const std_msgs::Header& header, const std::string& child,
                  const std::vector<double>& p, double heading) {
  nav_msgs::Odometry truth;
  truth.header = header;
  truth.child_frame_id = child;
  truth.pose.pose.position.x = p[0];
  truth.pose.pose.position.y = p[1];
  truth.pose.pose.position.z = p[2];
  truth.pose.pose.orientation.z = std::sin(0.5 * heading);
  truth.pose.pose.orientation.w = std::cos(0.5 * heading);
  pub.publish(truth);
}
}  // namespace

RobotSimNode::RobotSimNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  const int id = requiredParam<int>(pnh, "id");
  id_ = id;
  if (id < 0) throw InvalidInput("~id: must be >= 0, got " + std::to_string(id));
  const std::vector<double> initial = requiredParam<std::vector<double>>(pnh, "initial_position");
  const double rate = optionalParam(pnh, "rate", 100.0);
  const std::string kinematics = optionalParam<std::string>(pnh, "kinematics", "holonomic");
  const int seed = optionalParam(pnh, "seed", id);
  cmdTimeout_ = optionalParam(pnh, "cmd_timeout", cmdTimeout_);
  // The default ~frame_prefix is the namespace: "/formation/robot_0" -> "formation/robot_0/".
  const std::string prefix = optionalParam(pnh, "frame_prefix", framePrefix(nh));
  worldFrame_ = worldFrame(pnh);
  std::string described;
  try {
    requireFiniteAbove("rate", rate, 0.0, "Hz");
    requireFiniteAtLeast("seed", seed, 0.0, "");
    requireFiniteAtLeast("cmd_timeout", cmdTimeout_, 0.0, "s");
    if (kinematics == "holonomic") {
      PointRobotSettings settings;
      settings.lag = optionalParam(pnh, "lag", settings.lag);
      settings.maxSpeed = optionalParam(pnh, "max_speed", settings.maxSpeed);
      settings.maxAcceleration = optionalParam(pnh, "max_acceleration", settings.maxAcceleration);
      settings.odometryNoise = optionalParam(pnh, "odometry_noise", settings.odometryNoise);
      point_ = std::make_unique<PointRobot>(settings, initial, static_cast<std::uint64_t>(seed));
      dimension_ = point_->dimension();
      described = "holonomic, lag " + formatNumber(settings.lag) + " s, max speed " +
                  formatNumber(settings.maxSpeed) + " m/s, max acceleration " +
                  formatNumber(settings.maxAcceleration) + " m/s^2, odometry noise " +
                  formatNumber(settings.odometryNoise) + " m";
    } else if (kinematics == "unicycle") {
      UnicycleRobotSettings settings;
      settings.lag = optionalParam(pnh, "lag", settings.lag);
      settings.maxSpeed = optionalParam(pnh, "max_speed", settings.maxSpeed);
      settings.maxTurnRate = optionalParam(pnh, "max_turn_rate", settings.maxTurnRate);
      settings.odometryNoise = optionalParam(pnh, "odometry_noise", settings.odometryNoise);
      settings.headingNoise = optionalParam(pnh, "heading_noise", settings.headingNoise);
      const double handOffset = optionalParam(pnh, "hand_offset", 0.1);
      requireFiniteAbove("hand_offset", handOffset, 0.0, "m");
      if (initial.size() != 2) {
        throw InvalidInput("kinematics: a unicycle drives on the plane; initial_position has " +
                           std::to_string(initial.size()) + " values");
      }
      const int headingSeed = optionalParam(pnh, "heading_seed", 0);
      requireFiniteAtLeast("heading_seed", headingSeed, 0.0, "");
      const double heading =
          pnh.hasParam("initial_heading") ? requiredParam<double>(pnh, "initial_heading")
                                          : drawInitialHeading(static_cast<std::uint64_t>(headingSeed), id);
      if (!std::isfinite(heading)) throw InvalidInput("initial_heading: must be finite, got " + formatNumber(heading));
      unicycle_ = std::make_unique<UnicycleRobot>(settings, axleFromHandPoint(initial.data(), heading, handOffset),
                                                  static_cast<std::uint64_t>(seed));
      described = "unicycle, heading " + formatNumber(heading) + " rad, hand point " + formatNumber(handOffset) +
                  " m ahead, lag " + formatNumber(settings.lag) + " s, max speed " +
                  formatNumber(settings.maxSpeed) + " m/s, max turn rate " + formatNumber(settings.maxTurnRate) +
                  " rad/s, odometry noise " + formatNumber(settings.odometryNoise) + " m, " +
                  formatNumber(settings.headingNoise) + " rad";
    } else {
      throw InvalidInput("kinematics: expected holonomic or unicycle, got '" + kinematics + "'");
    }
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string("~") + e.what());  // the core names the parameter without '~'
  }
  childFrame_ = prefix + "base_link";
  setUpContacts(nh, pnh, id);
  odomPub_ = nh.advertise<nav_msgs::Odometry>("odom", 100);
  commandSub_ = nh.subscribe("cmd_vel", 100, &RobotSimNode::onCommand, this, ros::TransportHints().tcpNoDelay());
  timer_ = nh.createTimer(ros::Duration(1.0 / rate), &RobotSimNode::onTimer, this);
  ROS_INFO("%s: robot %d (%s in %s) at %s%s, %s; %g Hz, seed %d, cmd_vel timeout %g s",
           ros::this_node::getName().c_str(), id, childFrame_.c_str(), worldFrame_.c_str(),
           formatNumber(initial[0]).c_str(),
           (", " + formatNumber(initial[1]) + (initial.size() > 2 ? ", " + formatNumber(initial[2]) : "")).c_str(),
           described.c_str(), rate, seed, cmdTimeout_);
}

void RobotSimNode::run() { ros::spin(); }

void RobotSimNode::onCommand(const geometry_msgs::Twist::ConstPtr& msg) {
  try {
    if (unicycle_) {
      unicycle_->setCommand(msg->linear.x, msg->linear.y, msg->angular.z);  // linear.y is ignored
    } else {
      std::vector<double> u{msg->linear.x, msg->linear.y, msg->linear.z};
      u.resize(static_cast<std::size_t>(dimension_));  // planar robots ignore z
      point_->setCommand(u);
    }
    lastCommand_ = ros::Time::now();
    stopped_ = false;
  } catch (const InvalidInput& e) {
    ++malformed_;
    ROS_WARN_THROTTLE(1.0, "%s: dropped a cmd_vel: %s; %ld dropped so far", ros::this_node::getName().c_str(),
                      e.what(), malformed_);
  }
}

void RobotSimNode::onTimer(const ros::TimerEvent&) {
  const ros::Time now = ros::Time::now();
  if (!stopped_ && cmdTimeout_ > 0.0 && (now - lastCommand_).toSec() > cmdTimeout_) {
    if (unicycle_) unicycle_->setCommand(0.0, 0.0, 0.0);
    else point_->setCommand(std::vector<double>(static_cast<std::size_t>(dimension_), 0.0));
    stopped_ = true;
    ROS_WARN("%s: no cmd_vel for %g s: stopping", ros::this_node::getName().c_str(), cmdTimeout_);
  }
  // The robot models are exact (or to 1e-7 m/s) for any interval: advance by the time that passed.
  if (!lastTick_.isZero() && now > lastTick_) {
    if (unicycle_) unicycle_->advance((now - lastTick_).toSec());
    else point_->advance((now - lastTick_).toSec());
  }
  lastTick_ = now;
  publish(now);
  if (counting_) checkContacts(now);
}

void RobotSimNode::publish(const ros::Time& stamp) {
  nav_msgs::Odometry odom;
  odom.header.stamp = stamp;
  odom.header.frame_id = worldFrame_;
  odom.child_frame_id = childFrame_;
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = worldFrame_;
  if (unicycle_) {
    const PlanarPose measured = unicycle_->measuredPose(), truth = unicycle_->pose();
    odom.pose.pose.position.x = measured.x;
    odom.pose.pose.position.y = measured.y;
    odom.pose.pose.orientation.z = std::sin(0.5 * measured.heading);
    odom.pose.pose.orientation.w = std::cos(0.5 * measured.heading);
    const double variance = unicycle_->settings().odometryNoise * unicycle_->settings().odometryNoise;
    odom.pose.covariance[0] = variance;
    odom.pose.covariance[7] = variance;
    odom.pose.covariance[35] = unicycle_->settings().headingNoise * unicycle_->settings().headingNoise;
    odom.twist.twist.linear.x = unicycle_->linearVelocity();  // in base_link
    odom.twist.twist.angular.z = unicycle_->angularVelocity();
    odomPub_.publish(odom);
    geometry_msgs::TransformStamped tf = frameAt(header, childFrame_, {truth.x, truth.y, 0.0});
    tf.transform.rotation.z = std::sin(0.5 * truth.heading);
    tf.transform.rotation.w = std::cos(0.5 * truth.heading);
    tf_.sendTransform(tf);
    if (contacts_) {
      contacts_->setPosition(id_, truth.x, truth.y);  // the body's centre: the axle
      publishTruth(truthPub_, header, childFrame_, {truth.x, truth.y, 0.0}, truth.heading);
    }
    return;
  }
  const std::vector<double>& p = point_->position();
  const std::vector<double>& v = point_->velocity();
  const std::vector<double> measured = point_->measuredPosition();
  const bool planar = dimension_ == 2;
  odom.pose.pose.position.x = measured[0];
  odom.pose.pose.position.y = measured[1];
  odom.pose.pose.position.z = planar ? 0.0 : measured[2];
  odom.pose.pose.orientation.w = 1.0;  // a point robot: base_link keeps the world's axes
  const double variance = point_->settings().odometryNoise * point_->settings().odometryNoise;
  odom.pose.covariance[0] = variance;
  odom.pose.covariance[7] = variance;
  odom.pose.covariance[14] = planar ? 0.0 : variance;
  odom.twist.twist.linear.x = v[0];  // base_link and world axes agree
  odom.twist.twist.linear.y = v[1];
  odom.twist.twist.linear.z = planar ? 0.0 : v[2];
  odomPub_.publish(odom);
  tf_.sendTransform(frameAt(header, childFrame_, {p[0], p[1], planar ? 0.0 : p[2]}));
  if (contacts_) {
    contacts_->setPosition(id_, p[0], p[1], planar ? 0.0 : p[2]);
    publishTruth(truthPub_, header, childFrame_, {p[0], p[1], planar ? 0.0 : p[2]}, 0.0);
  }
}

}  // namespace vf
