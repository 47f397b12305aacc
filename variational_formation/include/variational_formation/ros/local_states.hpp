#pragma once

#include <vector>

#include <ros/ros.h>

#include "variational_formation_msgs/AgentState.h"
#include "variational_formation_core/protocol/local_exchange.hpp"

namespace vf {

/**
 * An agent_manager's LocalExchange of its own agents' states (doc/distributed.md, "Local
 * delivery"): the agents of ~agents, in the manager's namespace, hand their states to each other
 * through it instead of through roscpp. One per process, started by agent_manager before it loads
 * its agents; agents loaded in any other process, or in another namespace, have none.
 */
class LocalStates {
 public:
  using Exchange = LocalExchange<variational_formation_msgs::AgentState::ConstPtr>;

  /// Starts this process's exchange for agents `ids` in the namespace of `nh`.
  static void start(const ros::NodeHandle& nh, const std::vector<int>& ids);
  /// Ends it (after the agents were unloaded).
  static void stop();
  /// The exchange of the agents in the namespace of `nh`; nullptr if this process has none for it.
  static Exchange* of(const ros::NodeHandle& nh);
  /// Hosted agent `id` runs its callbacks on `queue` (set when it is constructed).
  static void place(int id, ros::CallbackQueueInterface* queue);
  /// The queue of hosted agent `id`; nullptr if not placed (yet) or not hosted.
  static ros::CallbackQueueInterface* queueOf(int id);
};

}  // namespace vf
