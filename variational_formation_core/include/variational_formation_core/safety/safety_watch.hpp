#pragma once

#include <map>
#include <string>
#include <vector>

#include "variational_formation_core/agents/blocked_detector.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/model/spatial_grid.hpp"

namespace vf {

/**
 * What the monitor reports of the safety filter (doc/ros_api.md, "monitor"), without ROS: the
 * closest pair at each measured step (a SpatialGrid, O(n) per step), the agents'
 * constraints_active summed, the closest approach and the steps the filter bound over the run,
 * and whether the formation is blocked (BlockedDetector, the one simulate uses). The agents whose
 * constraints bind at a step are taken as the ones that block each other.
 *
 * Lockstep measures every agent's state at one step: note() keeps the values by step. Timed mode
 * measures each agent's newest state: note() keeps the newest per agent.
 */
class SafetyWatch {
 public:
  /**
   * @param scenario a validated scenario (with or without a safety block: without, nothing binds).
   * @param blockedAfter [s] > 0. @param timed which states a step measures (above).
   * @throws InvalidInput on a bad blockedAfter.
   */
  SafetyWatch(const Scenario& scenario, double blockedAfter, bool timed);

  /// Agent `agent`'s AgentState.constraints_active at `step`, as accepted by the monitor.
  void note(int agent, long step, long constraintsActive);

  /**
   * One measured step, in order. @param q its positions (d x n) [m]. @param error its max
   * distance error [m]. @param congruent whether it has the desired shape.
   * @return whether the formation is blocked from this step on.
   */
  bool observe(long step, const Positions& q, double error, bool congruent);

  /// Of the last observed step: its closest pair distance [m] and the constraints active, summed.
  double minSeparation() const { return last_.distance; }
  const ClosestPair& lastPair() const { return last_; }
  long constraintsActive() const { return active_; }
  /// Over the run: the closest pair (+inf before a step) and its step; steps with a binding constraint.
  const ClosestPair& closestApproach() const { return closest_; }
  long closestApproachStep() const { return closestStep_; }
  long filterActiveSteps() const { return filterActiveSteps_; }
  bool blocked() const { return blocked_.blocked(); }
  /// "blocked: agents 2, 4" once blocked.
  std::string description() const { return blocked_.description(); }
  /// The result file's lines: "closest_approach: {distance: D, agents: [i, j], step: K}" and
  /// "filter_active_steps: N".
  std::string resultLines() const;

 private:
  int agents_;
  double hint_;  // the grid's first cell size [m]
  bool timed_;
  BlockedDetector blocked_;
  std::map<long, std::vector<long>> byStep_;  // lockstep: step -> each agent's constraints_active
  std::vector<long> newest_;                  // timed: each agent's newest
  std::vector<long> newestStep_;
  ClosestPair last_, closest_;
  long closestStep_ = -1;
  long active_ = 0;
  long filterActiveSteps_ = 0;
  std::vector<int> binding_;
};

}  // namespace vf
