#include "variational_formation_core/integrators/delayed_variational_integrator.hpp"

#include <cmath>
#include <string>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/model/metrics.hpp"

namespace vf {

void validateDelaySettings(const DelaySettings& s) {
  if (s.delaySteps < 0) {
    throw InvalidInput("--delay-steps: must be an integer >= 0, got " + std::to_string(s.delaySteps));
  }
  if (!(s.lossProbability >= 0.0 && s.lossProbability <= 1.0)) {
    throw InvalidInput("--loss: must be a probability in [0, 1], got " + formatNumber(s.lossProbability));
  }
}

bool LossPattern::lost() {
  ++draws_;
  const double u = static_cast<double>(engine_() >> 11) * 0x1.0p-53;  // [0, 1), 53 bits
  const bool isLost = u < probability_;
  losses_ += isLost ? 1 : 0;
  return isLost;
}

DelayedVariationalIntegrator::DelayedVariationalIntegrator(
    const Formation& formation, const Positions& q0, const Positions& v0, double timeStep,
    double dampingGain, StartMethod start, const DelaySettings& delay)
    : Integrator(formation, timeStep, dampingGain),
      coefficients_(timeStep, dampingGain),
      start_(start),
      delay_(delay),
      loss_(delay.lossProbability, delay.seed),
      v0_(v0),
      qPrev_(q0),
      q_(q0),
      qNext_(q0),
      view_(q0) {
  validateDelaySettings(delay);
  history_.assign(static_cast<std::size_t>(delay.delaySteps + 1), q0);
  const int n = formation.agentCount();
  const int d = formation.dimension();
  held_.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    for (const Neighbour& nb : formation.neighbours(i)) {
      held_[i].insert(held_[i].end(), q0.col(nb.agent).data(), q0.col(nb.agent).data() + d);
    }
  }
}

void DelayedVariationalIntegrator::step() {
  const int d = formation_.dimension();
  const int n = formation_.agentCount();
  const long slots = delay_.delaySteps + 1;
  // States sent at m = k - D arrive now; q_j^0 is known to everyone from the start.
  const long m = step_ - delay_.delaySteps;
  if (m >= 1) {
    const Positions& sent = history_[static_cast<std::size_t>(m % slots)];
    for (int i = 0; i < n; ++i) {
      double* held = held_[i].data();
      for (const Neighbour& nb : formation_.neighbours(i)) {
        if (delay_.lossProbability == 0.0 || !loss_.lost()) {
          for (int a = 0; a < d; ++a) held[a] = sent(a, nb.agent);
        }
        held += d;
      }
    }
  }
  double g[3];
  for (int i = 0; i < n; ++i) {
    // Agent i's view: its own q_i^k and what it holds of each neighbour.
    for (int a = 0; a < d; ++a) view_(a, i) = q_(a, i);
    const double* held = held_[i].data();
    for (const Neighbour& nb : formation_.neighbours(i)) {
      for (int a = 0; a < d; ++a) view_(a, nb.agent) = held[a];
      held += d;
    }
    forces_.agentGradient(i, view_, g);
    variationalStep(coefficients_, start_, step_, d, qPrev_.col(i).data(), q_.col(i).data(),
                    v0_.col(i).data(), g, qNext_.col(i).data());
  }
  qPrev_.swap(q_);
  q_.swap(qNext_);
  ++step_;
  history_[static_cast<std::size_t>(step_ % slots)] = q_;
}

Positions DelayedVariationalIntegrator::velocities() const {
  if (step_ == 0) return v0_;
  return (q_ - qPrev_) / timeStep_;
}

Positions DelayedVariationalIntegrator::momenta() const {
  if (step_ == 0) return v0_;
  return discreteMomentumPlus(formation_, coefficients_, qPrev_, q_);
}

double DelayedVariationalIntegrator::energy() const {
  if (step_ == 0) return continuousEnergy(formation_, q_, v0_);
  return discreteEnergy(formation_, timeStep_, qPrev_, q_);
}

void runDelayedScenario(const Scenario& scenario, StartMethod start, const DelaySettings& delay,
                        const std::function<bool(const Integrator&)>& observe) {
  if (scenario.steps <= 0) {
    throw InvalidInput("steps: must be >= 1 for a centralised run (0 = unbounded is only for the ROS run)");
  }
  const Formation formation = makeFormation(scenario);
  DelayedVariationalIntegrator integrator(formation, scenario.initialPositions,
                                          scenario.initialVelocities, scenario.timeStep,
                                          scenario.dampingGain, start, delay);
  if (!observe(integrator)) return;
  for (long k = 0; k < scenario.steps; ++k) {
    integrator.step();
    if (!observe(integrator)) return;
  }
}

}  // namespace vf
