#pragma once

#include <deque>
#include <memory>
#include <vector>

#include <ros/ros.h>

#include "variational_formation/AgentState.h"
#include "variational_formation/FormationStatus.h"
#include "variational_formation/core/monitor.hpp"

namespace vf {

using variational_formation::AgentState;
using variational_formation::FormationStatus;

/**
 * ROS I/O of the monitor: subscribes to every agent's state, publishes /formation/status and
 * /formation/markers for each completed step, and reports convergence. Maths: FormationMonitor.
 * Private parameters: ~scenario (required), ~trail_length (default 100), ~status_subscribers and
 * ~marker_subscribers (subscribers to wait for before publishing step 0, default 0).
 */
class MonitorNode {
 public:
  /// @throws InvalidInput on a missing or bad parameter or scenario.
  MonitorNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  /// Runs until the scenario's last step is published (forever for steps: 0) or shutdown.
  void run();

 private:
  void onState(int expectedSender, const AgentState::ConstPtr& msg);
  void publishCompleted();

  std::unique_ptr<FormationMonitor> monitor_;
  std::vector<ros::Subscriber> subs_;
  ros::Publisher statusPub_, markersPub_;
  std::vector<std::deque<Eigen::Vector3d>> trails_;
  int trailLength_ = 100;
  int statusSubscribers_ = 0;
  int markerSubscribers_ = 0;
  long dropped_ = 0;
  long reportedConvergence_ = -2;
  ros::WallTime firstStepAt_;
};

}  // namespace vf
