#pragma once

#include <functional>
#include <iosfwd>

#include "variational_formation/core/integrator.hpp"
#include "variational_formation/core/manoeuvre_command.hpp"
#include "variational_formation/core/scenario.hpp"

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
};

/// Energy, largest edge distance error (against s d_ij, s the commanded scale), momenta and
/// tracking at the integrator's current step.
StepMetrics measure(const Integrator& integrator);

/**
 * Runs a validated scenario for scenario.steps updates, calling observe at steps 0..steps.
 * @throws InvalidInput if scenario.steps is 0 (unbounded runs are for the ROS nodes).
 */
void runScenario(const Scenario& scenario, Method method, StartMethod start,
                 const std::function<void(const Integrator&)>& observe);

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
/// Writes "step,t,energy,max_distance_error,px,py,pz,ax,ay,az,cvx,cvy,cvz,wx,wy,wz,scale_error,shape_error".
void writeMetricsHeader(std::ostream& out);
void writeMetricsRow(std::ostream& out, const StepMetrics& m);

}  // namespace vf
