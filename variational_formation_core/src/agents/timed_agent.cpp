#include "variational_formation_core/agents/timed_agent.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/model/validation.hpp"

namespace vf {

namespace {

bool allFinite(const std::vector<double>& q) {
  for (double x : q) {
    if (!std::isfinite(x)) return false;
  }
  return true;
}

void checkPosition(const char* field, const std::vector<double>& q, int dimension) {
  if (static_cast<int>(q.size()) != dimension) {
    throw InvalidInput(std::string(field) + ": expected " + std::to_string(dimension) + " values, got " +
                       std::to_string(q.size()));
  }
  for (double x : q) {
    if (!std::isfinite(x)) throw InvalidInput(std::string(field) + ": must be finite, got " + formatNumber(x));
  }
}

}  // namespace

TimedAgent::TimedAgent(const Scenario& scenario, int id, double maxAge, StartMethod start)
    : neighbourhood_(scenario, id),
      coefficients_(scenario.timeStep, scenario.dampingGain),
      start_(start),
      steps_(scenario.steps),
      dimension_(scenario.dimension),
      maxAge_(maxAge) {
  requireFiniteAbove("max_age", maxAge, 0.0, "s");
  q_ = neighbourhood_.initialPosition();
  qPrev_ = q_;
  v_ = neighbourhood_.initialVelocity();
  neighbours_.resize(static_cast<std::size_t>(scenario.agentCount()));
  schedule_ = scheduleFromSegments(scenario.manoeuvre, scenario.timeStep);
}

void TimedAgent::setCommand(const Command& command) {
  validateCommand(command, dimension_, coefficients_.timeStep, CommandFieldNames::keys("command"));
  if (command.rotates() && !neighbourhood_.motion().exact) throw InvalidInput(neighbourhood_.motion().problem);
  liveCommand_ = command;
  live_ = true;
}

Command TimedAgent::command() const { return live_ ? liveCommand_ : schedule_.at(step_); }

std::string TimedAgent::describe(Receipt receipt) {
  switch (receipt) {
    case Receipt::Accepted: return "accepted";
    case Receipt::Outdated: return "not newer than the held state";
    case Receipt::UnknownSender: return "unknown sender";
    case Receipt::WrongDimension: return "wrong dimension";
    case Receipt::NonFinite: return "non-finite value";
    case Receipt::NegativeStep: return "negative step";
  }
  return "?";
}

void TimedAgent::enableSafety(const Scenario& scenario, double maxSpeed, double handOffset) {
  if (!scenario.safety) throw InvalidInput("safety: the scenario has no safety block");
  safety_.emplace(scenario, id(), maxSpeed, handOffset);
}

TimedAgent::Receipt TimedAgent::receive(long sender, long step, const std::vector<double>& position,
                                        const std::vector<double>& previousPosition, double now, double sentAt) {
  Receipt receipt = accept(sender, step, position, previousPosition, now);
  if (safety_ && (receipt == Receipt::Accepted || receipt == Receipt::UnknownSender) && sender >= 0 &&
      sender < static_cast<long>(neighbours_.size()) && sender != id()) {
    // Any agent of the formation may come within the sensing radius: the filter keeps them all.
    if (static_cast<int>(position.size()) != dimension_) {
      receipt = Receipt::WrongDimension;
    } else if (!allFinite(position) || !allFinite(previousPosition)) {
      receipt = Receipt::NonFinite;
    } else if (step < 0) {
      receipt = Receipt::NegativeStep;
    } else {
      safety_->hold(static_cast<int>(sender), position.data(), std::isnan(sentAt) ? now : sentAt);
      if (receipt == Receipt::UnknownSender) receipt = Receipt::Accepted;  // not a neighbour: the filter's only
    }
  }
  if (receipt == Receipt::Accepted) {
    ++accepted_;
  } else {
    ++dropped_;
    if (receipt != Receipt::UnknownSender) ++neighbours_[static_cast<std::size_t>(sender)].dropped;
  }
  return receipt;
}

TimedAgent::Receipt TimedAgent::accept(long sender, long step, const std::vector<double>& position,
                                       const std::vector<double>& previousPosition, double now) {
  switch (neighbourhood_.check(sender, position, previousPosition)) {
    case AgentNeighbourhood::StateCheck::Usable: break;
    case AgentNeighbourhood::StateCheck::UnknownSender: return Receipt::UnknownSender;
    case AgentNeighbourhood::StateCheck::WrongDimension: return Receipt::WrongDimension;
    case AgentNeighbourhood::StateCheck::NonFinite: return Receipt::NonFinite;
  }
  if (step < 0) return Receipt::NegativeStep;
  NeighbourState& held = neighbours_[static_cast<std::size_t>(sender)];
  // Keyed by receive time: after a silence longer than maxAge any state is news (a respawned
  // neighbour may count from a lower step); before that only a higher step is.
  const bool silent = now - held.receivedAt > maxAge_;
  if (held.heard && step <= held.step && !silent) return Receipt::Outdated;
  held.heard = true;
  held.step = step;
  held.receivedAt = now;
  held.position = position;
  held.previousPosition = previousPosition;
  ++held.accepted;
  return Receipt::Accepted;
}

TimedAgent::NeighbourStatus TimedAgent::status(int j, double now) const {
  const NeighbourState& held = neighbours_[static_cast<std::size_t>(j)];
  NeighbourStatus s;
  s.id = j;
  s.heard = held.heard;
  s.step = held.step;
  s.age = held.heard ? now - held.receivedAt : std::numeric_limits<double>::infinity();
  s.stale = !held.heard || s.age > maxAge_;
  s.accepted = held.accepted;
  s.dropped = held.dropped;
  return s;
}

std::vector<TimedAgent::NeighbourStatus> TimedAgent::neighbourStatus(double now) const {
  std::vector<NeighbourStatus> all;
  for (int j : neighbourIds()) all.push_back(status(j, now));
  return all;
}

TimedAgent::TickResult TimedAgent::tick(double now) {
  TickResult result;
  for (int j : neighbourIds()) {
    NeighbourStatus s = status(j, now);
    if (s.stale) result.stale.push_back(s);
  }
  if (safety_) {
    // The filter needs every agent's position once: where an agent is unknown, no step is safe.
    for (int j : safety_->unheard()) {
      if (std::find(neighbourIds().begin(), neighbourIds().end(), j) == neighbourIds().end()) {
        result.stale.push_back(status(j, now));
      }
    }
  }
  tickNow_ = now;
  constraintsActive_ = 0;
  foreignConstraintsActive_ = 0;
  if (!result.stale.empty()) {
    hold();
  } else {
    if (measured_) q_ = qMeasured_;
    const auto neighbourPosition = [this](int j) { return neighbours_[static_cast<std::size_t>(j)].position.data(); };
    double gradient[3], offset[3] = {0.0, 0.0, 0.0};
    if (!live_ && schedule_.empty()) {
      neighbourhood_.gradient(q_.data(), neighbourPosition, gradient);  // no command: today's update
      move(gradient, nullptr, nullptr);
    } else {
      // As LockstepAgent: the node gains between the previous tick's command and this one's.
      const ManoeuvreGains now = manoeuvreGains(command(), coefficients_);
      // Before the first command the agent moved with none: the zero command's gains.
      const ManoeuvreGains before = haveLastGains_ ? lastGains_ : manoeuvreGains(Command{}, coefficients_);
      const ManoeuvreGains g = started_ && !restart_ ? nodeGains(before, now) : now;
      neighbourhood_.forcedGradient(q_.data(), neighbourPosition, g.scaleSquared, g.rotates, gradient, offset);
      move(gradient, &g, offset);
      lastGains_ = now;
      haveLastGains_ = true;
    }
  }
  measured_ = false;
  ++step_;
  result.step = step_;
  result.holding = holding_;
  return result;
}

void TimedAgent::hold() {
  if (measured_) q_ = qMeasured_;
  qPrev_ = q_;
  // Before the first move the start from (q_0, v_0) is only deferred; afterwards the agent
  // has stopped, so it restarts from rest.
  if (started_) {
    restart_ = true;
    v_.assign(static_cast<std::size_t>(dimension_), 0.0);
  }
  holding_ = true;
  ++heldTicks_;
}

void TimedAgent::move(const double* gradient, const ManoeuvreGains* g, const double* offset) {
  std::vector<double> next(static_cast<std::size_t>(dimension_));
  const double h = coefficients_.timeStep;
  if (!started_ || restart_) {
    const std::vector<double> zero(static_cast<std::size_t>(dimension_), 0.0);
    const std::vector<double>& vStart = restart_ ? zero : neighbourhood_.initialVelocity();
    if (start_ == StartMethod::Variational && g) {
      manoeuvreStart(coefficients_, *g, dimension_, q_.data(), vStart.data(), gradient, offset, next.data());
    } else if (start_ == StartMethod::Variational) {
      variationalStart(coefficients_, dimension_, q_.data(), vStart.data(), gradient, next.data());
    } else {
      paperStart(coefficients_, dimension_, q_.data(), vStart.data(), next.data());
    }
    for (int a = 0; a < dimension_; ++a) v_[a] = (next[a] - q_[a]) / h;
  } else if (measured_) {
    // Robot mode: q_k measured, v_{k-1} from our own command; the noise of q_k is not divided by h.
    std::vector<double> vNext(static_cast<std::size_t>(dimension_));
    if (g) {
      // The forced update from q_{k-1} = q_k - h v_{k-1}: the same velocity form.
      std::vector<double> before(static_cast<std::size_t>(dimension_));
      for (int a = 0; a < dimension_; ++a) before[a] = q_[a] - h * v_[a];
      manoeuvreUpdate(coefficients_, *g, dimension_, before.data(), q_.data(), gradient, offset, next.data());
      for (int a = 0; a < dimension_; ++a) vNext[a] = (next[a] - q_[a]) / h;
    } else {
      variationalVelocityUpdate(coefficients_, dimension_, v_.data(), gradient, vNext.data());
    }
    for (int a = 0; a < dimension_; ++a) next[a] = q_[a] + h * vNext[a];
    v_.swap(vNext);
  } else if (g) {
    manoeuvreUpdate(coefficients_, *g, dimension_, qPrev_.data(), q_.data(), gradient, offset, next.data());
    for (int a = 0; a < dimension_; ++a) v_[a] = (next[a] - q_[a]) / h;
  } else {
    // doc/maths.md §2, explicit update, as in VariationalIntegrator::step.
    variationalUpdate(coefficients_, dimension_, qPrev_.data(), q_.data(), gradient, next.data());
    for (int a = 0; a < dimension_; ++a) v_[a] = (next[a] - q_[a]) / h;
  }
  if (safety_) {
    // doc/robots.md "Safety": the same filter as every run, on the step just computed.
    const SafeStep& filtered = safety_->filter(tickNow_, q_.data(), next.data());
    constraintsActive_ = safety_->constraintsActive();
    foreignConstraintsActive_ = safety_->foreignConstraintsActive();
    if (filtered.projection.changed) {
      for (int a = 0; a < dimension_; ++a) v_[a] = (next[a] - q_[a]) / h;
    }
  }
  qPrev_.swap(q_);
  q_.swap(next);
  started_ = true;
  restart_ = false;
  holding_ = false;
}

void TimedAgent::setMeasuredPosition(const std::vector<double>& position) {
  checkPosition("measured position", position, dimension_);
  qMeasured_ = position;
  measured_ = true;
}

void TimedAgent::setDampingGain(double dampingGain) {
  validateDynamics(coefficients_.timeStep, dampingGain);  // the scenario's check of kappa
  coefficients_ = VariationalCoefficients(coefficients_.timeStep, dampingGain);
}

void TimedAgent::restore(long step, const std::vector<double>& position) {
  checkPosition("restored position", position, dimension_);
  if (step < 0) throw InvalidInput("restored step: must be >= 0, got " + std::to_string(step));
  q_ = position;
  qPrev_ = position;
  v_.assign(static_cast<std::size_t>(dimension_), 0.0);
  step_ = step;
  started_ = true;
  restart_ = true;
  measured_ = false;
}

}  // namespace vf
