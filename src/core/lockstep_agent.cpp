#include "variational_formation/core/lockstep_agent.hpp"

#include <cmath>

#include "variational_formation/core/error.hpp"
#include "variational_formation/core/validation.hpp"

namespace vf {

LockstepAgent::LockstepAgent(const Scenario& scenario, int id, StartMethod start)
    : scenario_(scenario),
      neighbourhood_(scenario, id),  // checks the id
      coefficients_(scenario.timeStep, scenario.dampingGain),
      start_(start),
      id_(id),
      dimension_(scenario.dimension) {
  q_ = neighbourhood_.initialPosition();
  qPrev_ = q_;
  qBeforePrev_ = q_;
  neighbours_.resize(static_cast<std::size_t>(scenario.agentCount()));
  if (!scenario.manoeuvre.empty()) {
    manoeuvre_ = std::make_unique<ManoeuvreModel>(coefficients_,
                                                  scheduleFromSegments(scenario.manoeuvre, scenario.timeStep));
  }
}

LockstepAgent::CommandReceipt LockstepAgent::receiveCommand(long step, const Command& command, std::string* error) {
  // Late only for an interval this incarnation has used: after a resume, before its first
  // update, the commands of the steps before it are still to come (the latched list).
  if (step < step_ && advanced_) return CommandReceipt::Late;
  try {
    validateCommand(command, dimension_, coefficients_.timeStep, CommandFieldNames::keys("command"));
  } catch (const InvalidInput& e) {
    if (error) *error = e.what();
    return CommandReceipt::Invalid;
  }
  if (command.rotates() && !neighbourhood_.motion().exact) {
    if (error) *error = neighbourhood_.motion().problem;
    return CommandReceipt::CannotTurn;
  }
  if (!manoeuvre_) manoeuvre_ = std::make_unique<ManoeuvreModel>(coefficients_, CommandSchedule{});
  manoeuvre_->replaceFrom(step, command);
  return CommandReceipt::Accepted;
}

const CommandSchedule& LockstepAgent::commands() const {
  static const CommandSchedule none;
  return manoeuvre_ ? manoeuvre_->schedule() : none;
}

std::string LockstepAgent::describe(Receipt receipt) {
  switch (receipt) {
    case Receipt::Accepted: return "accepted";
    case Receipt::Duplicate: return "duplicate";
    case Receipt::UnknownSender: return "unknown sender";
    case Receipt::WrongDimension: return "wrong dimension";
    case Receipt::NonFinite: return "non-finite value";
    case Receipt::ImpossibleStep: return "a step that cannot come next";
  }
  return "?";
}

LockstepAgent::Receipt LockstepAgent::receive(long sender, long step,
                                              const std::vector<double>& position,
                                              const std::vector<double>& previousPosition) {
  switch (neighbourhood_.check(sender, position, previousPosition)) {
    case AgentNeighbourhood::StateCheck::UnknownSender: return Receipt::UnknownSender;
    case AgentNeighbourhood::StateCheck::WrongDimension: return Receipt::WrongDimension;
    case AgentNeighbourhood::StateCheck::NonFinite: return Receipt::NonFinite;
    case AgentNeighbourhood::StateCheck::Usable: break;
  }
  NeighbourState& held = neighbours_[static_cast<std::size_t>(sender)];
  // A neighbour is at most one step ahead, and never goes back.
  if (step < 0 || step > step_ + 1) return Receipt::ImpossibleStep;
  if (step == held.step) return Receipt::Duplicate;
  if (step < held.step) return Receipt::ImpossibleStep;
  held.step = step;
  held.position = position;
  held.previousPosition = previousPosition;
  return Receipt::Accepted;
}

const double* LockstepAgent::neighbourPositionAtStep(const NeighbourState& s) const {
  if (s.step == step_) return s.position.data();
  if (s.step == step_ + 1) return s.previousPosition.data();
  return nullptr;
}

bool LockstepAgent::holdsNeighbourStep(int j) const {
  return j >= 0 && j < static_cast<int>(neighbours_.size()) &&
         neighbourPositionAtStep(neighbours_[static_cast<std::size_t>(j)]) != nullptr;
}

bool LockstepAgent::neighbourState(int j, long& step, std::vector<double>& position,
                                   std::vector<double>& previousPosition) const {
  if (j < 0 || j >= static_cast<int>(neighbours_.size())) return false;
  const NeighbourState& s = neighbours_[static_cast<std::size_t>(j)];
  if (s.step < 0) return false;
  step = s.step;
  position = s.position;
  previousPosition = s.previousPosition;
  return true;
}

bool LockstepAgent::ready() const {
  for (int j : neighbourIds()) {
    if (!neighbourPositionAtStep(neighbours_[static_cast<std::size_t>(j)])) return false;
  }
  return true;
}

void LockstepAgent::advance() {
  if (!ready()) throw InvalidInput("advance: a neighbour's state at step " + std::to_string(step_) + " is missing");
  std::vector<double> next(static_cast<std::size_t>(dimension_));
  if (manoeuvre_) {
    manoeuvreStep(next.data());
  } else {
    double gradient[3];
    neighbourhood_.gradient(
        q_.data(), [this](int j) { return neighbourPositionAtStep(neighbours_[static_cast<std::size_t>(j)]); },
        gradient);
    variationalStep(coefficients_, start_, step_, dimension_, qPrev_.data(), q_.data(),
                    neighbourhood_.initialVelocity().data(), gradient, next.data());
  }
  qBeforePrev_.swap(qPrev_);
  qPrev_.swap(q_);
  q_.swap(next);
  ++step_;
  advanced_ = true;
}

// doc/maths.md §9, as in ManoeuvreIntegrator::step.
void LockstepAgent::manoeuvreStep(double* next) {
  const ManoeuvreGains g = manoeuvre_->updateGains(step_);
  double gradient[3], offset[3] = {0.0, 0.0, 0.0};
  neighbourhood_.forcedGradient(
      q_.data(), [this](int j) { return neighbourPositionAtStep(neighbours_[static_cast<std::size_t>(j)]); },
      g.scaleSquared, g.rotates, gradient, offset);
  if (step_ > 0) {
    manoeuvreUpdate(coefficients_, g, dimension_, qPrev_.data(), q_.data(), gradient, offset, next);
  } else if (start_ == StartMethod::Variational) {
    manoeuvreStart(coefficients_, g, dimension_, q_.data(), neighbourhood_.initialVelocity().data(), gradient, offset,
                   next);
  } else {
    paperStart(coefficients_, dimension_, q_.data(), neighbourhood_.initialVelocity().data(), next);
  }
}

void LockstepAgent::resume(long step, const std::vector<double>& position,
                           const std::vector<double>& previousPosition) {
  if (step < 0) throw InvalidInput("resume: step must be >= 0, got " + std::to_string(step));
  if (static_cast<int>(position.size()) != dimension_ || static_cast<int>(previousPosition.size()) != dimension_) {
    throw InvalidInput("resume: expected " + std::to_string(dimension_) + " coordinates");
  }
  for (int a = 0; a < dimension_; ++a) {
    if (!std::isfinite(position[a]) || !std::isfinite(previousPosition[a])) throw InvalidInput("resume: non-finite state");
  }
  step_ = step;
  q_ = position;
  qPrev_ = previousPosition;
  qBeforePrev_ = previousPosition;
  advanced_ = false;
}

bool LockstepAgent::finite() const {
  for (int a = 0; a < dimension_; ++a) {
    if (!std::isfinite(q_[a]) || !std::isfinite(qPrev_[a])) return false;
  }
  return true;
}

void LockstepAgent::undo() {
  if (step_ == 0) return;
  q_.swap(qPrev_);
  qPrev_.swap(qBeforePrev_);
  --step_;
}

}  // namespace vf
