#pragma once

#include "variational_formation_core/agents/blocked_detector.hpp"
#include "variational_formation_core/model/formation.hpp"
#include "variational_formation_core/integrators/integrator.hpp"
#include "variational_formation_core/manoeuvres/command_schedule.hpp"
#include "variational_formation_core/agents/run_verdict.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/model/spatial_grid.hpp"

namespace vf {

/**
 * The outcome of a centralised run, judged step by step as the monitor judges a distributed one:
 * congruence with the desired shape (1% on every pair, speeds below 0.1 m/s relative to the
 * commanded motion), and under a safety filter the closest approach, the steps the filter bound
 * and whether the formation is blocked (BlockedDetector).
 */
class RunTracker {
 public:
  /// @param schedule the commands the run applies (empty: none). Both must outlive the tracker.
  RunTracker(const Scenario& scenario, const CommandSchedule& schedule);

  /// Step k of the run, in order. @return false once the run is blocked (it should stop there).
  bool observe(const Integrator& integrator);

  /// "converged at step K (t = T s)", "not converged (final max distance error E m)" or
  /// "not converged (blocked: agents 2, 4)", of the last observed step.
  FormationOutcome outcome() const;
  /// First step of the congruent stretch that holds at the last observed step (-1: none).
  long convergedStep() const { return convergedStep_; }
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
  long convergedStep_ = -1;
  double lastError_ = 0.0;
  ClosestPair closest_;
  long closestStep_ = -1;
  long filterActiveSteps_ = 0;
};

}  // namespace vf
