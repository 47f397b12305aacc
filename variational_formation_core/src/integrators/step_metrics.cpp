#include "variational_formation_core/integrators/step_metrics.hpp"

#include <cstdio>
#include <limits>
#include <memory>
#include <ostream>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/validation.hpp"
#include "variational_formation_core/manoeuvres/manoeuvre_integrator.hpp"
#include "variational_formation_core/model/metrics.hpp"
#include "variational_formation_core/safety/safety_stage.hpp"
#include "variational_formation_core/manoeuvres/commanded_frame.hpp"

namespace vf {

StepMetrics measure(const Integrator& integrator, bool withShapeError) {
  StepMetrics m;
  m.step = integrator.stepIndex();
  m.time = integrator.time();
  m.energy = integrator.energy();
  const double scale = integrator.commandedScale();
  m.maxDistanceError = integrator.formation().maxDistanceError(integrator.positions(), scale);
  const Momenta p = integrator.momenta();
  m.linearMomentum = linearMomentum(p);
  m.angularMomentum = angularMomentum(integrator.positions(), p);
  const Velocities v = integrator.velocities();
  m.centroidVelocity = centroidVelocity(v);
  m.rotationRate = rotationRate(integrator.positions(), v, integrator.timeStep());
  m.scaleError = meanScaleError(integrator.formation(), integrator.positions(), scale);
  m.shapeError = withShapeError ? integrator.formation().shapeError(integrator.positions(), scale)
                                : std::numeric_limits<double>::quiet_NaN();
  if (SafetyStage* safety = integrator.safety()) {
    m.minSeparation = safety->closestPair(integrator.positions(), integrator.stepIndex()).distance;
  }
  return m;
}

std::shared_ptr<SafetyStage> makeSafetyStage(const Scenario& scenario) {
  if (!scenario.safety) return nullptr;
  return std::make_shared<SafetyStage>(*scenario.safety, scenario.obstacles, scenario.timeStep);
}

void checkSafetyMethod(const Scenario& scenario, Method method) {
  if (scenario.safety && method != Method::Variational) {
    throw InvalidInput("safety: the filter acts on the variational step; only with --method vi");
  }
}

void runCentralised(const Scenario& scenario, Method method, StartMethod start, const CommandSchedule* schedule,
                    const StepObserver& observe) {
  validateSteps(scenario.steps, /*requireBounded=*/true);
  checkSafetyMethod(scenario, method);
  const Formation formation = makeFormation(scenario);
  std::unique_ptr<Integrator> integrator;
  if (schedule) {
    integrator = std::make_unique<ManoeuvreIntegrator>(formation, scenario.initialPositions,
                                                       scenario.initialVelocities, scenario.timeStep,
                                                       scenario.dampingGain, start, *schedule);
  } else {
    integrator = makeIntegrator(method, formation, scenario.initialPositions, scenario.initialVelocities,
                                scenario.timeStep, scenario.dampingGain, start);
  }
  integrator->attachSafety(makeSafetyStage(scenario));
  if (!observe(*integrator)) return;
  for (long k = 0; k < scenario.steps; ++k) {
    integrator->step();
    if (!observe(*integrator)) return;
  }
}

void runScenario(const Scenario& scenario, Method method, StartMethod start,
                 const std::function<void(const Integrator&)>& observe) {
  runCentralised(scenario, method, start, nullptr, [&](const Integrator& integrator) {
    observe(integrator);
    return true;
  });
}

void runManoeuvre(const Scenario& scenario, StartMethod start, const CommandSchedule& schedule,
                  const std::function<void(const Integrator&)>& observe) {
  runCentralised(scenario, Method::Variational, start, &schedule, [&](const Integrator& integrator) {
    observe(integrator);
    return true;
  });
}

namespace {
void put(std::ostream& out, double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  out << buf;
}
}  // namespace

void writeTrajectoryHeader(std::ostream& out) { out << "step,t,agent,x,y,z\n"; }

void writeTrajectoryRows(std::ostream& out, long step, double time, const Positions& q) {
  for (Eigen::Index i = 0; i < q.cols(); ++i) {
    out << step << ',';
    put(out, time);
    out << ',' << i;
    for (Eigen::Index a = 0; a < 3; ++a) {
      out << ',';
      put(out, a < q.rows() ? q(a, i) : 0.0);
    }
    out << '\n';
  }
}

void writeMetricsHeader(std::ostream& out, bool withSeparation) {
  out << "step,t,energy,max_distance_error,px,py,pz,ax,ay,az,cvx,cvy,cvz,wx,wy,wz,scale_error,shape_error"
      << (withSeparation ? ",min_separation\n" : "\n");
}

void writeMetricsRow(std::ostream& out, const StepMetrics& m, bool withSeparation) {
  out << m.step;
  for (double x : {m.time, m.energy, m.maxDistanceError}) {
    out << ',';
    put(out, x);
  }
  for (int a = 0; a < 3; ++a) {
    out << ',';
    put(out, m.linearMomentum(a));
  }
  for (const Vector3* x : {&m.angularMomentum, &m.centroidVelocity, &m.rotationRate}) {
    for (int a = 0; a < 3; ++a) {
      out << ',';
      put(out, (*x)(a));
    }
  }
  for (double x : {m.scaleError, m.shapeError}) {
    out << ',';
    put(out, x);
  }
  if (withSeparation) {
    out << ',';
    put(out, m.minSeparation);
  }
  out << '\n';
}

}  // namespace vf
