#include "variational_formation_core/agents/formation_monitor.hpp"

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/model/metrics.hpp"
#include "variational_formation_core/manoeuvres/commanded_frame.hpp"

namespace vf {

FormationMonitor::FormationMonitor(const Scenario& scenario, double tolerance, double maxSpeed)
    : scenario_(scenario),
      formation_(makeFormation(scenario)),
      coefficients_(scenario.timeStep, scenario.dampingGain),
      schedule_(scheduleFromSegments(scenario.manoeuvre, scenario.timeStep)),
      tolerance_(tolerance),
      maxSpeed_(maxSpeed),
      congruence_(tolerance, maxSpeed) {
  p0_ = linearMomentum(scenario.initialVelocities);
  a0_ = angularMomentum(scenario.initialPositions, scenario.initialVelocities);
}

std::string FormationMonitor::describe(Receipt receipt) {
  switch (receipt) {
    case Receipt::Accepted: return "accepted";
    case Receipt::Duplicate: return "duplicate";
    case Receipt::UnknownAgent: return "unknown agent";
    case Receipt::WrongDimension: return "wrong dimension";
    case Receipt::NonFinite: return "non-finite value";
    case Receipt::ImpossibleStep: return "a step that cannot come yet";
  }
  return "?";
}

FormationMonitor::Receipt FormationMonitor::add(long id, long step, const std::vector<double>& position,
                                                const std::vector<double>& previousPosition, long lastAllowed) {
  const int n = formation_.agentCount();
  const int d = formation_.dimension();
  if (id < 0 || id >= n) return Receipt::UnknownAgent;
  if (static_cast<int>(position.size()) != d || static_cast<int>(previousPosition.size()) != d) {
    return Receipt::WrongDimension;
  }
  if (!finiteState(position, previousPosition)) return Receipt::NonFinite;
  if (step < 0 || step > lastAllowed || (scenario_.steps > 0 && step > scenario_.steps)) return Receipt::ImpossibleStep;
  if (step < next_) return Receipt::Duplicate;
  Pending& p = pending_[step];
  if (p.seen.empty()) {
    p.q.resize(d, n);
    p.qPrev.resize(d, n);
    p.seen.assign(static_cast<std::size_t>(n), false);
  }
  if (p.seen[static_cast<std::size_t>(id)]) return Receipt::Duplicate;
  p.seen[static_cast<std::size_t>(id)] = true;
  ++p.count;
  for (int a = 0; a < d; ++a) {
    p.q(a, id) = position[a];
    p.qPrev(a, id) = previousPosition[a];
  }
  return Receipt::Accepted;
}

void FormationMonitor::startAt(long step, long congruentSince) {
  if (step < 0) throw InvalidInput("startAt: step must be >= 0, got " + std::to_string(step));
  pending_.clear();
  next_ = step;
  congruentSince_ = congruentSince;
  mirrorTested_ = false;  // a restarted monitor tests the stretch it resumes in again
}

std::vector<int> FormationMonitor::missingAt(long step) const {
  std::vector<int> missing;
  const auto it = pending_.find(step);
  for (int i = 0; i < formation_.agentCount(); ++i) {
    if (it == pending_.end() || !it->second.seen[static_cast<std::size_t>(i)]) missing.push_back(i);
  }
  return missing;
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
  // The command of the interval that ends at t_k, as ManoeuvreModel::scaleAt and simulate take it.
  const Command& command = schedule_.at(step > 0 ? step - 1 : 0);
  const double scale = command.scale, scaleSquared = scale * scale;
  Positions p, v;
  if (step == 0) {
    v = scenario_.initialVelocities;
    p = v;
    s.metrics.energy = continuousEnergy(formation_, q, v, scaleSquared);
    s.agentEnergy = agentContinuousEnergy(formation_, q, v, scaleSquared);
  } else {
    v = (q - qPrev) / h;
    p = discreteMomentumPlus(formation_, coefficients_, qPrev, q);
    s.metrics.energy = discreteEnergy(formation_, h, qPrev, q, scaleSquared);
    s.agentEnergy = agentDiscreteEnergy(formation_, h, qPrev, q, scaleSquared);
  }
  s.metrics.step = step;
  s.metrics.time = static_cast<double>(step) * h;
  s.metrics.maxDistanceError = formation_.maxDistanceError(q, scale);
  s.metrics.linearMomentum = linearMomentum(p);
  s.metrics.angularMomentum = angularMomentum(q, p);
  s.linearMomentumPredicted = noetherPrediction(p0_, coefficients_, step);
  s.angularMomentumPredicted = noetherPrediction(a0_, coefficients_, step);
  s.edgeDistanceErrors = formation_.distanceErrors(q, scale);
  s.scale = scale;
  s.positions = q;
  subtractCommandedMotion(command, q, v);  // from here on, relative to the commanded motion
  s.congruent = congruence_.check(formation_, q, v, scale);
  // The O(n^2) shape error at most a 50-agent cost per step (NaN between).
  const bool measured = shapeErrorMeasuredAt(step, formation_.agentCount(), scenario_.steps);
  // The mirror test once per congruent stretch: its answer holds while the shape stays congruent.
  const bool mirrorKnown = s.congruent && congruentSince_ >= 0 && mirrorTested_;
  s.shape = findShape(formation_, q, v, scale, s.congruent, tolerance_, maxSpeed_, measured,
                      mirrorKnown ? &mirrored_ : nullptr, static_cast<double>(step) * h);
  mirrorTested_ = s.congruent;
  mirrored_ = s.shape.mirrored;
  if (!s.congruent) {
    congruentSince_ = -1;
  } else if (congruentSince_ < 0) {
    congruentSince_ = step;
  }
  // A congruent stretch keeps its hand (findShape): converged from its first step, or never.
  s.congruentSince = congruentSince_;
  s.converged = s.congruent && (!s.shape.mirrored || scenario_.mirrorAllowed);
  s.convergedStep = s.converged ? congruentSince_ : -1;
  return s;
}

}  // namespace vf
