#pragma once

#include <memory>
#include <set>
#include <string>

#include "variational_formation_core/common/types.hpp"
#include "variational_formation_core/safety/foreign_agents.hpp"

namespace vf {

/**
 * What the monitor reports of the other formations (doc/ros_api.md, "monitor"; doc/maths.md §10,
 * "Other formations"), without ROS: the closest pair of the formation's agents at a measured step
 * and the other formations' agents as last heard (ForeignAgents::closest), the closest such pair
 * over the run, and the steps at which some agent's filter bound on another formation's agent
 * (AgentState.foreign_constraints_active): from the first, a lockstep run depends on the other
 * formation's timing and cannot equal simulate.
 */
class ForeignWatch {
 public:
  /// @param agents what the monitor hears of the other formations (not null).
  explicit ForeignWatch(std::shared_ptr<const ForeignAgents> agents);

  /// Agent `agent`'s foreign_constraints_active at `step`. @return true the first time one is > 0
  /// in the run (the monitor says so once).
  bool note(long step, long foreignConstraintsActive);
  /// One measured step: its positions q (d x n) [m]. @return the closest foreign pair at it.
  const ClosestForeign& observe(long step, const Positions& q);

  /// Steps at which some agent's filter bound on another formation's agent.
  long constraintSteps() const { return static_cast<long>(steps_.size()); }
  /// Of the run: the closest foreign pair (distance +inf while none is heard) and its step (-1).
  const ClosestForeign& closestApproach() const { return closest_; }
  long closestApproachStep() const { return closestStep_; }
  /// The result file's lines: "closest_foreign_approach: {distance: D, agents: [agent_i, NAME],
  /// step: K}" ("~" while none was heard) and "foreign_constraint_steps: N".
  std::string resultLines() const;

 private:
  std::shared_ptr<const ForeignAgents> agents_;
  std::set<long> steps_;
  ClosestForeign last_, closest_;
  long closestStep_ = -1;
};

}  // namespace vf
