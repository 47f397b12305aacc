#pragma once
// An agent's subscriptions to its neighbours' states and the monitor's progress; commands
// from their messages.

#include <functional>
#include <vector>

#include <ros/ros.h>

#include "variational_formation_core/manoeuvres/command_schedule.hpp"
#include "variational_formation_msgs/AgentState.h"
#include "variational_formation_msgs/FormationCommand.h"
#include "variational_formation_msgs/RunProgress.h"

namespace vf {

/// An agent's subscriptions (lockstep or timed): each neighbour's `agent_<j>/state` with queue
/// `stateQueue`, and the monitor's `progress`, with TCP_NODELAY, callbacks on nh's queue.
void subscribeToFormation(
    ros::NodeHandle& nh, const std::vector<int>& neighbours, uint32_t stateQueue,
    const std::function<void(int, const ros::MessageEvent<variational_formation_msgs::AgentState const>&)>& onState,
    const std::function<void(const ros::MessageEvent<variational_formation_msgs::RunProgress const>&)>& onProgress,
    std::vector<ros::Subscriber>& states, ros::Subscriber& progress);

/// The command of a FormationCommand message (its step aside).
Command commandOf(const variational_formation_msgs::FormationCommand& message);

}  // namespace vf
