#include "variational_formation/core/monitor.hpp"

#include <cmath>

#include "variational_formation/core/metrics.hpp"

namespace vf {

FormationMonitor::FormationMonitor(const Scenario& scenario, double tolerance, double maxSpeed)
    : scenario_(scenario),
      formation_(makeFormation(scenario)),
      coefficients_(scenario.timeStep, scenario.dampingGain),
      tolerance_(tolerance),
      maxSpeed_(maxSpeed) {
  p0_ = linearMomentum(scenario.initialVelocities);
  a0_ = angularMomentum(scenario.initialPositions, scenario.initialVelocities);
}

bool FormationMonitor::add(long id, long step, const std::vector<double>& position,
                           const std::vector<double>& previousPosition) {
  const int n = formation_.agentCount();
  const int d = formation_.dimension();
  if (id < 0 || id >= n || step < next_) return false;
  if (scenario_.steps > 0 && step > scenario_.steps) return false;
  if (static_cast<int>(position.size()) != d || static_cast<int>(previousPosition.size()) != d) return false;
  for (int a = 0; a < d; ++a) {
    if (!std::isfinite(position[a]) || !std::isfinite(previousPosition[a])) return false;
  }
  Pending& p = pending_[step];
  if (p.seen.empty()) {
    p.q.resize(d, n);
    p.qPrev.resize(d, n);
    p.seen.assign(static_cast<std::size_t>(n), false);
  }
  if (p.seen[static_cast<std::size_t>(id)]) return false;
  p.seen[static_cast<std::size_t>(id)] = true;
  ++p.count;
  for (int a = 0; a < d; ++a) {
    p.q(a, id) = position[a];
    p.qPrev(a, id) = previousPosition[a];
  }
  return true;
}

std::vector<FormationSnapshot> FormationMonitor::takeCompleted() {
  std::vector<FormationSnapshot> done;
  for (auto it = pending_.find(next_); it != pending_.end() && it->second.count == formation_.agentCount();
       it = pending_.find(next_)) {
    done.push_back(measureStep(next_, it->second.qPrev, it->second.q));
    pending_.erase(it);
    ++next_;
  }
  return done;
}

FormationSnapshot FormationMonitor::measureStep(long step, const Positions& qPrev, const Positions& q) {
  FormationSnapshot s;
  const double h = coefficients_.timeStep;
  Positions p, v;
  if (step == 0) {
    v = scenario_.initialVelocities;
    p = v;
    s.metrics.energy = continuousEnergy(formation_, q, v);
    s.agentEnergy = agentContinuousEnergy(formation_, q, v);
  } else {
    v = (q - qPrev) / h;
    p = discreteMomentumPlus(formation_, coefficients_, qPrev, q);
    s.metrics.energy = discreteEnergy(formation_, h, qPrev, q);
    s.agentEnergy = agentDiscreteEnergy(formation_, h, qPrev, q);
  }
  s.metrics.step = step;
  s.metrics.time = static_cast<double>(step) * h;
  s.metrics.maxDistanceError = formation_.maxDistanceError(q);
  s.metrics.linearMomentum = linearMomentum(p);
  s.metrics.angularMomentum = angularMomentum(q, p);
  s.linearMomentumPredicted = noetherPrediction(p0_, coefficients_, step);
  s.angularMomentumPredicted = noetherPrediction(a0_, coefficients_, step);
  s.edgeDistanceErrors = formation_.distanceErrors(q);
  s.positions = q;
  s.converged = formation_.isCongruent(q, v, tolerance_, maxSpeed_);
  if (!s.converged) {
    congruentSince_ = -1;
  } else if (congruentSince_ < 0) {
    congruentSince_ = step;
  }
  s.convergedStep = congruentSince_;
  return s;
}

}  // namespace vf
