#pragma once

#include <memory>
#include <string>

#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include "variational_formation/core/point_robot.hpp"
#include "variational_formation/core/unicycle_robot.hpp"

namespace vf {

/**
 * A simulated robot behind the interfaces of a real one (doc/robots.md), ~kinematics:
 * - holonomic (core PointRobot): tracks `cmd_vel` linear (world axes);
 * - unicycle (core UnicycleRobot, a differential drive): tracks linear.x and angular.z, ignores
 *   linear.y; it starts at the heading ~initial_heading, or one drawn from ~heading_seed, with its
 *   hand point (~hand_offset ahead of the axle) at ~initial_position.
 * It publishes `odom` (nav_msgs/Odometry: noisy pose of base_link in ~world_frame, twist in
 * base_link) and the tf world_frame -> <prefix>base_link of the true pose, both in ROS time. The
 * prefix is the node's namespace ("formation/robot_0/"). Topics are relative: run one per robot
 * in its own namespace, or remap them. Private parameters: doc/ros_api.md, "robot_sim" (a robot
 * stops when its commands stop for ~cmd_timeout).
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

  std::unique_ptr<PointRobot> point_;       // holonomic
  std::unique_ptr<UnicycleRobot> unicycle_; // unicycle
  int dimension_ = 2;
  ros::Subscriber commandSub_;
  ros::Publisher odomPub_;
  tf2_ros::TransformBroadcaster tf_;
  ros::Timer timer_;
  std::string childFrame_, worldFrame_;
  double cmdTimeout_ = 0.5;
  ros::Time lastCommand_, lastTick_;
  bool stopped_ = true;  // no command, or the last one timed out
  long malformed_ = 0;
};

}  // namespace vf
