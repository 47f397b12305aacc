// The time-driven agent's robot (TimedAgentNode in robot mode, timed_agent_node.hpp): the
// parameters of its RobotLink, the robot's topics, odometry in and cmd_vel out.
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/Twist.h>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/timed_agent_node.hpp"

namespace vf {

void TimedAgentNode::setUpRobot(ros::NodeHandle& nh, ros::NodeHandle& pnh, const Scenario& scenario, int id) {
  RobotLinkSettings s;
  try {
    s.kinematics = parseKinematics(optionalParam<std::string>(pnh, "kinematics", kinematicsName(s.kinematics)));
    s.feedback = parseFeedback(optionalParam<std::string>(pnh, "feedback", feedbackName(s.feedback)));
    s.hand.handOffset = optionalParam(pnh, "hand_offset", s.hand.handOffset);
    s.hand.maxSpeed = optionalParam(pnh, "max_speed", s.hand.maxSpeed);
    s.hand.maxTurnRate = optionalParam(pnh, "max_turn_rate", s.hand.maxTurnRate);
    s.lag = optionalParam(pnh, "robot_lag", s.lag);
    s.correctionTime = optionalParam(pnh, "correction_time", s.correctionTime);
    s.trackingGain = optionalParam(pnh, "tracking_gain", s.trackingGain);
    link_ = std::make_unique<RobotLink>(s, scenario.dimension, h_);
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string("~") + e.what());  // the core names the parameter without '~'
  }
  // Public topics in the robot's namespace, relative to the formation's: a robot driver's names.
  const std::string robotNs = optionalParam<std::string>(pnh, "robot_namespace", "robot_" + std::to_string(id));
  const std::string in = robotNs.empty() ? "" : robotNs + "/";
  odomFrames_ = std::make_unique<FrameGate>(worldFrame_, name_, "the agent holds until odometry in '" + worldFrame_ +
                                                                    "' comes");
  odomSub_ = nh.subscribe(in + "odom", 10, &TimedAgentNode::onOdometry, this, ros::TransportHints().tcpNoDelay());
  setpointPub_ = nh.advertise<geometry_msgs::PoseStamped>(in + "setpoint", 10);
  cmdVelPub_ = nh.advertise<geometry_msgs::Twist>(in + "cmd_vel", 10);
  lagCheck_ = checkRobotLag(scenario, s.lag, h_ / rate_, s.feedback, "~");
  if (!lagCheck_.warning.empty()) {
    ROS_WARN("%s: %s", name_.c_str(), lagCheck_.warning.c_str());
  } else {
    ROS_INFO("%s: %s", name_.c_str(), lagCheck_.info.c_str());
  }
}

void TimedAgentNode::onOdometry(const nav_msgs::Odometry& odom) {
  const auto& p = odom.pose.pose.position;
  const auto& o = odom.pose.pose.orientation;
  const bool first = !link_->measured();
  if (!odomFrames_->admit(odom.header.frame_id, odomSub_.getTopic())) return;
  try {
    link_->measureOdometry(p.x, p.y, p.z, o.x, o.y, o.z, o.w);
  } catch (const InvalidInput& e) {
    ++badOdometry_;
    ROS_WARN_THROTTLE(1.0, "%s: dropped an odometry message on %s: %s; %ld dropped so far", name_.c_str(),
                      odomSub_.getTopic().c_str(), e.what(), badOdometry_);
    return;
  }
  if (first) ROS_INFO("%s: first odometry on %s", name_.c_str(), odomSub_.getTopic().c_str());
}

void TimedAgentNode::sendCommand() {
  geometry_msgs::Twist cmd;  // zero: the run is over, our last step is done
  if (!agent_->finished()) {
    const RobotLink::Command c = link_->command(agent_->commandedVelocity(), agent_->previousPosition());
    cmd.linear.x = c.linear[0];
    cmd.linear.y = c.linear[1];
    cmd.linear.z = c.linear[2];
    cmd.angular.z = c.angular;
  }
  cmdVelPub_.publish(cmd);
}

}  // namespace vf
