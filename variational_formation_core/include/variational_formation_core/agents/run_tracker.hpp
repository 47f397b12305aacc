#pragma once

#include "variational_formation_core/agents/blocked_detector.hpp"
#include "variational_formation_core/model/formation.hpp"
#include "variational_formation_core/integrators/integrator.hpp"
#include "variational_formation_core/manoeuvres/command_schedule.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/model/spatial_grid.hpp"

namespace vf {

/**
 * A centralised run under a safety filter, judged step by step as the monitor judges a
 * distributed one: the closest approach, the steps the filter bound and whether the formation is
 * blocked (BlockedDetector, which needs congruence with the desired shape: 1% on every pair,
 * speeds below 0.1 m/s relative to the commanded motion). The shape's verdict is ShapeTracker's.
 */
class RunTracker {
 public:
  /// @param schedule the commands the run applies (empty: none). Both must outlive the tracker.
  RunTracker(const Scenario& scenario, const CommandSchedule& schedule);

  /// Step k of the run, in order. @return false once the run is blocked (it should stop there).
  bool observe(const Integrator& integrator);

  /// "blocked: agents 2, 4" (BlockedDetector::description()) once the run is blocked, else empty.
  std::string blockedBy() const { return blocked_.blocked() ? blocked_.description() : std::string(); }
  /// The closest pair over every observed step (distance +inf without a safety filter).
  const ClosestPair& closestApproach() const { return closest_; }
  long closestApproachStep() const { return closestStep_; }
  /// Steps in which some half-space of the filter bound.
  long filterActiveSteps() const { return filterActiveSteps_; }
  bool blocked() const { return blocked_.blocked(); }

 private:
  const Scenario& scenario_;
  const CommandSchedule& schedule_;
  CongruenceTracker congruence_;
  BlockedDetector blocked_;
  double lastError_ = 0.0;
  ClosestPair closest_;
  long closestStep_ = -1;
  long filterActiveSteps_ = 0;
};

}  // namespace vf
