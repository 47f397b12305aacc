#pragma once

#include <vector>

#include "variational_formation_core/safety/safety_filter.hpp"
#include "variational_formation_core/model/spatial_grid.hpp"

namespace vf {

/**
 * The safety filter over a whole formation, as the centralised run applies it (doc/maths.md §10):
 * after every agent's update q̂^{k+2} is computed from the step-(k+1) positions, each agent's
 * displacement is filtered with the step-(k+1) positions of the agents a SpatialGrid finds within
 * the sensing radius (ascending id), through filterNextPosition, the function every run calls.
 * It also keeps what the run reports: the closest pair and which constraints bind.
 */
class SafetyStage {
 public:
  /// @param timeStep h [s] (the speed limit is maxSpeed h per step).
  SafetyStage(const SafetySettings& settings, std::vector<Obstacle> obstacles, double timeStep);

  /**
   * Filters qNext (q̂^{k+2} in, q^{k+2} out, d x n) given q = q^{k+1}. Agents whose step nothing
   * binds keep their column untouched.
   * @param step k + 1, the index of q (the grid over q is built once per step, and reused by
   * closestPair at the same step).
   */
  void apply(const Positions& q, long step, Positions& qNext);
  /// The closest pair of q, the positions at `step` (found with the grid apply() then reuses).
  ClosestPair closestPair(const Positions& q, long step);

  /// Of the last apply(): the agents a binding half-space involves (each binding agent and the
  /// neighbours it binds against), ascending; empty if no half-space bound.
  const std::vector<int>& bindingAgents() const { return bindingAgents_; }
  /// Of the last apply(): the obstacles (list indices) that bind some agent, ascending.
  const std::vector<int>& bindingObstacles() const { return bindingObstacles_; }
  /// Of the last apply(): how many agents the speed limit held back.
  int speedLimitedAgents() const { return speedLimited_; }

  const SafetySettings& settings() const { return settings_; }
  const std::vector<Obstacle>& obstacles() const { return obstacles_; }

 private:
  void sense(const Positions& q, long step);

  SafetySettings settings_;
  std::vector<Obstacle> obstacles_;
  double timeStep_;
  SpatialGrid grid_;
  long sensedStep_ = -1;
  std::vector<int> sensedStart_, sensedIds_;  // whom each agent senses at sensedStep_ (ascending)
  std::vector<SensedAgent> scratch_;
  SafeStep step_;  // reused for every agent: no allocation per step
  std::vector<int> bindingAgents_, bindingObstacles_;
  int speedLimited_ = 0;
};

}  // namespace vf
