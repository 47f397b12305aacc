#pragma once

#include <functional>
#include <iosfwd>
#include <limits>
#include <memory>

#include "variational_formation_core/integrators/integrator.hpp"
#include "variational_formation_core/manoeuvres/command_schedule.hpp"
#include "variational_formation_core/model/scenario.hpp"

namespace vf {

/// The quantities written per step to metrics.csv and published by the monitor.
struct StepMetrics {
  long step = 0;
  double time = 0.0;
  double energy = 0.0;
  double maxDistanceError = 0.0;
  Vector3 linearMomentum = Vector3::Zero();
  Vector3 angularMomentum = Vector3::Zero();
  /// Tracking (tracking.hpp): centroid velocity [m/s], rotation rate [rad/s], mean scale error [1].
  Vector3 centroidVelocity = Vector3::Zero();
  Vector3 rotationRate = Vector3::Zero();
  double scaleError = 0.0;
  /// Formation::shapeError against s q*: over all pairs, so a folded shape shows [m]. O(n^2).
  double shapeError = 0.0;
  /// Closest pair distance [m] (only under a safety filter; NaN without one).
  double minSeparation = std::numeric_limits<double>::quiet_NaN();
};

/// Energy, largest edge distance error (against s d_ij, s the commanded scale), momenta and
/// tracking at the integrator's current step, and the closest pair if a safety filter is attached.
/// withShapeError false leaves shapeError NaN (the O(n^2) part; see shapeErrorMeasuredAt).
StepMetrics measure(const Integrator& integrator, bool withShapeError = true);

/**
 * Runs a validated scenario for scenario.steps updates, calling observe at steps 0..steps
 * (runCentralised: through the safety filter if the scenario has one).
 * @throws InvalidInput if scenario.steps is 0 (unbounded runs are for the ROS nodes).
 */
void runScenario(const Scenario& scenario, Method method, StartMethod start,
                 const std::function<void(const Integrator&)>& observe);

/// Called at steps 0..steps of a run; returning false ends the run after that step.
using StepObserver = std::function<bool(const Integrator&)>;

/// The safety filter of a scenario with `safety:` for the centralised run, nullptr without one.
std::shared_ptr<SafetyStage> makeSafetyStage(const Scenario& scenario);

/// @throws InvalidInput if the scenario has `safety:` and method is not Method::Variational.
void checkSafetyMethod(const Scenario& scenario, Method method);

/**
 * The centralised run of a validated scenario: runManoeuvre's if `schedule` is given (not
 * nullptr), runScenario's otherwise, with the scenario's safety filter attached if it has one
 * (doc/maths.md §10). Stops early when `observe` returns false. @throws InvalidInput as checkSafetyMethod.
 */
void runCentralised(const Scenario& scenario, Method method, StartMethod start, const CommandSchedule* schedule,
                    const StepObserver& observe);

/**
 * Runs a validated scenario under a command schedule (its `manoeuvre:` converted by
 * scheduleFromSegments, or a commands file) with the forced variational update
 * (ManoeuvreIntegrator), calling observe at steps 0..steps.
 */
void runManoeuvre(const Scenario& scenario, StartMethod start, const CommandSchedule& schedule,
                  const std::function<void(const Integrator&)>& observe);

/// Writes "step,t,agent,x,y,z" (z = 0 in 2D), 17 significant digits.
void writeTrajectoryHeader(std::ostream& out);
void writeTrajectoryRows(std::ostream& out, long step, double time, const Positions& q);
/// Writes "step,t,energy,max_distance_error,px,py,pz,ax,ay,az,cvx,cvy,cvz,wx,wy,wz,scale_error,shape_error",
/// and ",min_separation" if `withSeparation` (runs with a safety filter).
void writeMetricsHeader(std::ostream& out, bool withSeparation = false);
void writeMetricsRow(std::ostream& out, const StepMetrics& m, bool withSeparation = false);

}  // namespace vf
