#pragma once

#include <string>

#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include "variational_formation/AgentState.h"
#include "variational_formation/FormationStatus.h"
#include "variational_formation/core/lockstep_agent.hpp"

namespace vf {

using variational_formation::AgentState;
using variational_formation::FormationStatus;

/**
 * ROS I/O of one agent (DESIGN.md §3): subscribes to its neighbours' states, publishes its own
 * (latched) and the tf world -> agent_<id>. All maths is LockstepAgent's.
 * Private parameters: ~id, ~scenario (required), ~real_time_factor (0 = as fast as possible),
 * ~extra_subscribers (subscribers of the state topic besides the neighbours, default 1: the
 * monitor), ~tf_subscribers (subscribers of /tf to wait for, default 0).
 */
class AgentNode {
 public:
  /// @throws InvalidInput on a missing or bad parameter or scenario.
  AgentNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  /// Runs to the scenario's last step (forever for steps: 0) or until shutdown.
  void run();
  long dropped() const { return dropped_; }

 private:
  void onState(int expectedSender, const AgentState::ConstPtr& msg);
  void publish();
  void waitForSubscribers();

  std::unique_ptr<LockstepAgent> agent_;
  ros::Publisher statePub_;
  ros::Publisher tfProbe_;  // same /tf topic as the broadcaster: tells who listens
  std::vector<ros::Subscriber> subs_;
  tf2_ros::TransformBroadcaster tf_;
  double realTimeFactor_ = 0.0;
  int extraSubscribers_ = 1;
  int tfSubscribers_ = 0;
  long dropped_ = 0;
  std::string frame_;
};

}  // namespace vf
