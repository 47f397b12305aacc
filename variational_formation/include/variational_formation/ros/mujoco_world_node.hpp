#pragma once

#include <memory>
#include <string>
#include <vector>

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include "variational_formation_msgs/RunProgress.h"
#include "variational_formation/world/mujoco_world.hpp"

namespace vf {

/**
 * The MuJoCo world behind robots.launch world:=mujoco (doc/robots.md, "The MuJoCo world"): one
 * process for every robot of the scenario, each with robot_sim's interface in
 * `robot_<i>` below the node's namespace: it subscribes to `robot_<i>/cmd_vel` and publishes
 * `robot_<i>/odom`, `robot_<i>/joint_states` and tf world_frame -> <prefix>robot_<i>/base_link.
 * Contacts go to `~contacts` (WorldContact), the diagnostics and, once the monitor's run is over,
 * the result file. `~markers` (MarkerArray, ~marker_rate) draws the bodies, headings, obstacles
 * and contacts (world_markers.hpp). Time: paced to wall time by ~real_time_factor, or with
 * ~clock the world publishes /clock (as fast as it can with ~real_time_factor 0). The scenario's
 * `obstacles:` are static geoms of the built world. Parameters: doc/ros_api.md.
 */
class MujocoWorldNode {
 public:
  /// @throws InvalidInput naming a missing or bad parameter or a model MuJoCo refuses.
  MujocoWorldNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  /// Steps and publishes until shutdown. @throws InvalidInput if the physics becomes unstable.
  void run();

 private:
  struct RobotIo {
    ros::Subscriber command;
    ros::Publisher odom, joints;
    std::string frame;
    double lastCommand = -1.0;  // simulated time [s]; < 0: none yet
    bool stopped = true;
  };
  void onCommand(int robot, const geometry_msgs::Twist::ConstPtr& msg);
  void onProgress(const variational_formation_msgs::RunProgress::ConstPtr& msg);
  void advance(double until);
  void publish();
  ros::Time stamp() const;
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  void appendResult();

  std::unique_ptr<MujocoWorld> world_;
  std::vector<RobotIo> robots_;
  bool wheelOdometry_ = false, clock_ = false;
  double publishPeriod_ = 0.01, cmdTimeout_ = 0.5, realTimeFactor_ = 1.0;
  double markerPeriod_ = 0.05, nextMarkers_ = 0.0;  // simulated time [s]; period <= 0: no markers
  double agentRadius_ = 0.0;  // the monitor's agent spheres [m]: the heading arrows reach out of them
  std::string worldFrame_, resultFile_;
  bool resultWritten_ = false, runOver_ = false;
  long saturated_ = 0, malformed_ = 0;
  double achievedFactor_ = 0.0;
  ros::NodeHandle nh_;
  ros::Publisher contactPub_, clockPub_, markerPub_;
  ros::Subscriber progressSub_;
  tf2_ros::TransformBroadcaster tf_;
  diagnostic_updater::Updater diagnostics_;
};

}  // namespace vf
