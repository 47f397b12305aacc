#pragma once

#include <memory>
#include <string>

#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include "variational_formation/core/point_robot.hpp"

namespace vf {

/**
 * A simulated holonomic point robot (core PointRobot) behind the interfaces of a real one: it
 * tracks `cmd_vel` (geometry_msgs/Twist, linear part, world axes) and publishes `odom`
 * (nav_msgs/Odometry, noisy position, frame world) and the tf world -> <prefix>robot_<id>/base_link
 * (true position). Topics are relative: run one per robot in its own namespace, or remap them.
 * Private parameters: doc/ros_api.md, "robot_sim" (a robot stops when its commands stop for
 * ~cmd_timeout).
 */
class RobotSimNode {
 public:
  /// @throws InvalidInput naming a missing or bad parameter.
  RobotSimNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  /// Spins until shutdown.
  void run();

 private:
  void onCommand(const geometry_msgs::Twist::ConstPtr& msg);
  void onTimer(const ros::TimerEvent& event);
  void publish(const ros::Time& stamp);

  std::unique_ptr<PointRobot> robot_;
  ros::Subscriber commandSub_;
  ros::Publisher odomPub_;
  tf2_ros::TransformBroadcaster tf_;
  ros::Timer timer_;
  std::string childFrame_;
  double cmdTimeout_ = 0.5;
  ros::Time lastCommand_, lastTick_;
  bool stopped_ = true;  // no command, or the last one timed out
  long malformed_ = 0;
};

}  // namespace vf
