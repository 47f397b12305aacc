#pragma once

#include <memory>
#include <string>
#include <vector>

#include <ros/ros.h>

#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/agents/sensing_board.hpp"

namespace vf {

/**
 * The SensingBoard that the agents of one agent_manager share, one per formation namespace
 * (doc/distributed.md, "Sensing"): the manager's own agents put their states on it as they
 * publish them, and it takes the states of the formation's other agents (not in the manager's
 * ~agents) from their own topics, checked by caller id, on the global queue. So the manager
 * holds one copy of every state and builds one spatial index per step for all its agents.
 */
class SensingHub {
 public:
  /// The board of the formation in nh's namespace; nullptr outside an agent_manager (no
  /// StateBatch), where every agent keeps a board of its own. @param managers ~agent_manager.
  static std::shared_ptr<SensingBoard> board(ros::NodeHandle& nh, const Scenario& scenario,
                                             const std::vector<std::string>& managers);
  /// Drops every board and subscription of the process (the manager, before ROS shuts down).
  static void stop();
};

}  // namespace vf
