#pragma once

#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <ros/ros.h>

#include "variational_formation/AgentState.h"
#include "variational_formation/AgentStates.h"

namespace vf {

/**
 * An agent manager's batch of its agents' states (doc/distributed.md, "Batches"): the agents
 * loaded in this process add each state they publish, and it goes out on the manager's `~states`
 * as one AgentStates once every agent of ~agents has added one, or 5 ms after the first state it
 * holds. The monitor and the recorder then take one message and one wake-up per step from a
 * manager instead of one per agent. One per process, started by agent_manager before it loads
 * its agents; agents in any other process have none. Thread-safe: the manager's workers add.
 */
class StateBatch {
 public:
  /// Starts this process's batch for agents `ids`, on `pnh`'s `states` (the manager's private handle).
  static void start(ros::NodeHandle& pnh, const std::vector<int>& ids);
  /// This process's batch; nullptr if it has none.
  static StateBatch* local();

  /// Ends this process's batch (before ROS shuts down).
  static void stop();

  /// A state its agent just published; states of agents not in ~agents are left out.
  void add(const variational_formation::AgentState::ConstPtr& state);

 private:
  StateBatch(ros::NodeHandle& pnh, const std::vector<int>& ids);
  void flush();
  /// A subscriber that connects gets each agent's newest state at once, as the latched
  /// agent_<i>/state topics give it (a monitor or recorder started late misses nothing).
  void onConnect(const ros::SingleSubscriberPublisher& subscriber);

  std::set<int> ids_;
  std::mutex mutex_;
  variational_formation::AgentStatesPtr pending_;
  std::map<int, variational_formation::AgentState::ConstPtr> newest_;
  ros::Publisher pub_;
  ros::WallTimer timer_;
};

/// Agents `ids` whose states come batched from `manager` (its full name).
struct BatchSource {
  std::string manager;
  std::set<int> ids;
};

/**
 * The managers among `managers` (full names) that batch their agents' states: each agent_manager
 * publishes its ~agents parameter, and only it batches. An agent listed by two managers is left
 * to its own topic. @param agents the formation's size: ids beyond it are ignored.
 */
std::vector<BatchSource> batchSources(const ros::NodeHandle& nh, const std::vector<std::string>& managers, int agents);

/// The agent ids in ~agents text ("0 1 2"). @throws InvalidInput naming `parameter`.
std::vector<int> parseAgentIds(const std::string& list, const std::string& parameter);

}  // namespace vf
