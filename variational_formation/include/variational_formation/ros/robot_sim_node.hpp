#pragma once

#include <memory>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include "variational_formation_core/robots/point_robot.hpp"
#include "variational_formation_msgs/RunProgress.h"
#include "variational_formation_core/robots/unicycle_robot.hpp"
#include "variational_formation/world/body_contacts.hpp"

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
 *
 * Body contacts (~robots > 0, doc/robots.md "Contacts"): it publishes its true pose on
 * `ground_truth`. With ~count_contacts (the default when ~result_file is given) it also reads the
 * other robots' (robot_<j>/ground_truth beside its own namespace) and counts every pair whose
 * bodies are closer than 2 ~body_radius (BodyContacts, counted as the MuJoCo world counts them),
 * on ~contacts (WorldContact) and in its diagnostics; with ~result_file, once the monitor's
 * `progress` says the run is over, it adds `contacts:` and `first_contact:` to that file, as
 * mujoco_world does.
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
  /// Contacts (~robots > 0): the topics, and the check after each advance.
  void setUpContacts(ros::NodeHandle& nh, ros::NodeHandle& pnh, int id);
  void checkContacts(const ros::Time& stamp);
  void onProgress(const variational_formation_msgs::RunProgress::ConstPtr& msg);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

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
  int id_ = 0;
  std::unique_ptr<BodyContacts> contacts_;  // ~robots > 0
  bool counting_ = false;                   // ~count_contacts: it reads every robot's pose
  ros::Publisher truthPub_, contactPub_;
  std::vector<ros::Subscriber> others_;
  ros::Subscriber progressSub_;
  std::string resultFile_;
  ros::Time origin_;        // contact times count from here: the run's start, else the first tick
  bool runStarted_ = false;
  bool runOver_ = false;  // the monitor's progress says so: add the lines to the result file
  bool resultWritten_ = false;
  std::unique_ptr<diagnostic_updater::Updater> diagnostics_;
};

}  // namespace vf
