#pragma once

#include <vector>

#include <memory>

#include "variational_formation_core/safety/foreign_agents.hpp"
#include "variational_formation_core/safety/safety_filter.hpp"
#include "variational_formation_core/model/scenario.hpp"

namespace vf {

/**
 * The margin [m] by which a time-driven agent widens r for another agent whose newest position
 * was sent `age` [s] ago (doc/robots.md, "Safety"): the distance that agent can have covered
 * since, age x maxSpeed. A negative age (clocks a hair apart) counts as 0.
 * @param maxSpeed [m/s] > 0, finite.
 */
double stalenessMargin(double age, double maxSpeed);

/**
 * The speed [m/s] that bounds every agent's published position in timed and robot mode: the
 * scenario's safety.max_speed, else `robotDefault` (robot mode: the speed the robot link
 * saturates cmd_vel at), else none can be given.
 * @param robotDefault [m/s], NaN outside robot mode.
 * @throws InvalidInput "safety.max_speed: ..." in timed mode without one (nothing bounds the
 * other agents' motion, so no margin is sound).
 */
double timedSafetySpeed(const SafetySettings& settings, double robotDefault);

/**
 * The safety filter of one time-driven agent (doc/robots.md, "Safety"): it keeps the newest
 * position of every other agent of the formation (not only its graph neighbours: sensing is by
 * distance), and filters the agent's step with filterNextPosition, the function every run calls,
 * with each position widened by its staleness margin. For a unicycle the hand points are
 * filtered, and the axle sits handOffset behind each, so r and R grow by 2 handOffset (the
 * obstacles' clearance r/2 by handOffset). The agent's own step is capped at maxSpeed h, so that
 * its published positions move no faster than the speed the others' margins assume.
 */
class TimedSafety {
 public:
  /**
   * @param scenario a validated scenario with a safety block. @param id the agent's id.
   * @param maxSpeed [m/s] (timedSafetySpeed). @param handOffset l [m] >= 0 (0: holonomic).
   * @throws InvalidInput on a bad maxSpeed or handOffset.
   */
  TimedSafety(const Scenario& scenario, int id, double maxSpeed, double handOffset);

  /// Keeps agent j's position (d doubles [m]) sent at `sentAt` [s] if it is newer than the held
  /// one. @return whether it was kept. Ids outside the formation, or the agent's own, are not.
  bool hold(int j, const double* position, double sentAt);
  /// Agents never heard (ascending): their position is unknown, so the agent must not move.
  std::vector<int> unheard() const;

  /**
   * Filters qNext (q̂^{k+2} in, q^{k+2} out) at time `now` [s], q = q^{k+1}.
   * @return the step: its constraints and projection (projection.changed: qNext was moved).
   */
  const SafeStep& filter(double now, const double* q, double* qNext);

  /// r, R (grown by 2 handOffset) and the step cap that apply.
  const SafetySettings& settings() const { return settings_; }
  double maxSpeed() const { return maxSpeed_; }
  /// Half-spaces and speed limit that bound the last filtered step (AgentState.constraints_active).
  int constraintsActive() const;
  /**
   * Also keeps r from the agents of other formations as last heard (doc/maths.md §10, "Other
   * formations"), as from the formation's own: each widened by its age x maxSpeed
   * (ForeignMargin::Age; `sentAt` of ForeignAgents::hold on the clock of filter()'s `now`).
   * nullptr: none (the default).
   */
  void avoid(std::shared_ptr<const ForeignAgents> foreign) { foreign_ = std::move(foreign); }
  /// Of constraintsActive(), the half-spaces of other formations' agents.
  int foreignConstraintsActive() const;

 private:
  struct Held {
    bool heard = false;
    double sentAt = 0.0;
    double position[3] = {0.0, 0.0, 0.0};
  };
  SafetySettings settings_;
  std::vector<Obstacle> obstacles_;
  double maxSpeed_, timeStep_;
  int dimension_, id_;
  std::vector<Held> held_;  // by agent id
  std::vector<SensedAgent> sensed_;
  std::shared_ptr<const ForeignAgents> foreign_;
  SafeStep step_;
};

}  // namespace vf
