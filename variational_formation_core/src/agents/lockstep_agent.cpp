#include "variational_formation_core/agents/lockstep_agent.hpp"

#include <algorithm>
#include <cmath>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/validation.hpp"

namespace vf {

LockstepAgent::LockstepAgent(const Scenario& scenario, int id, StartMethod start, std::shared_ptr<SensingBoard> board)
    : LockstepAgent(std::make_shared<const Scenario>(scenario), nullptr, id, start, std::move(board)) {}

LockstepAgent::LockstepAgent(std::shared_ptr<const Scenario> shared, std::shared_ptr<const Formation> formation, int id,
                             StartMethod start, std::shared_ptr<SensingBoard> board)
    : scenario_(std::move(shared)),
      neighbourhood_(*scenario_, id, std::move(formation)),  // checks the id
      coefficients_(scenario_->timeStep, scenario_->dampingGain),
      start_(start),
      id_(id),
      dimension_(scenario_->dimension) {
  const Scenario& scenario = *scenario_;
  q_ = neighbourhood_.initialPosition();
  qPrev_ = q_;
  qBeforePrev_ = q_;
  const std::vector<int>& ids = neighbourhood_.neighbourIds();
  neighbours_.resize(ids.size());
  for (std::size_t k = 0; k < ids.size(); ++k) slots_.emplace_back(ids[k], static_cast<int>(k));
  std::sort(slots_.begin(), slots_.end());
  spare_.assign(static_cast<std::size_t>(dimension_), 0.0);
  if (!scenario.manoeuvre.empty()) {
    manoeuvre_ = std::make_unique<ManoeuvreModel>(coefficients_,
                                                  scheduleFromSegments(scenario.manoeuvre, scenario.timeStep));
  }
  if (scenario.safety) {
    board_ = board ? std::move(board)
                   : std::make_shared<SensingBoard>(scenario.agentCount(), dimension_, scenario.safety->sensingRadius);
    if (board_->agentCount() != scenario.agentCount() || board_->dimension() != dimension_) {
      throw InvalidInput("sensing: a board of " + std::to_string(board_->agentCount()) + " agents for a formation of " +
                         std::to_string(scenario.agentCount()));
    }
    offerOwn();
  }
}

const LockstepAgent::NeighbourState* LockstepAgent::held(long j) const {
  const auto it = std::lower_bound(slots_.begin(), slots_.end(), j,
                                   [](const std::pair<int, int>& s, long id) { return s.first < id; });
  return it != slots_.end() && it->first == j ? &neighbours_[static_cast<std::size_t>(it->second)] : nullptr;
}

void LockstepAgent::offerOwn() {
  if (board_ && finite()) board_->offer(id_, step_, q_.data(), qPrev_.data());
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
  if (board_ && sender != id_ && sender >= 0 && sender < scenario_->agentCount() && !isNeighbour(sender)) {
    // A sensed agent (doc/distributed.md, "Sensing"): the barrier keeps it within one step, as
    // a neighbour.
    if (position.size() != static_cast<std::size_t>(dimension_) ||
        previousPosition.size() != static_cast<std::size_t>(dimension_)) {
      return Receipt::WrongDimension;
    }
    if (step > step_ + 1) return Receipt::ImpossibleStep;
    switch (board_->offer(sender, step, position.data(), previousPosition.data())) {
      case SensingBoard::Offer::Accepted: return Receipt::Accepted;
      case SensingBoard::Offer::Duplicate: return Receipt::Duplicate;
      case SensingBoard::Offer::UnknownSender: return Receipt::UnknownSender;
      case SensingBoard::Offer::NonFinite: return Receipt::NonFinite;
      case SensingBoard::Offer::GoesBack: return Receipt::ImpossibleStep;
    }
  }
  switch (neighbourhood_.check(sender, position, previousPosition)) {
    case AgentNeighbourhood::StateCheck::UnknownSender: return Receipt::UnknownSender;
    case AgentNeighbourhood::StateCheck::WrongDimension: return Receipt::WrongDimension;
    case AgentNeighbourhood::StateCheck::NonFinite: return Receipt::NonFinite;
    case AgentNeighbourhood::StateCheck::Usable: break;
  }
  NeighbourState& state = *held(sender);  // check() accepts neighbours only
  // A neighbour is at most one step ahead, and never goes back.
  if (step < 0 || step > step_ + 1) return Receipt::ImpossibleStep;
  if (step == state.step) return Receipt::Duplicate;
  if (step < state.step) return Receipt::ImpossibleStep;
  state.step = step;
  state.position = position;
  state.previousPosition = previousPosition;
  if (board_) board_->offer(sender, step, position.data(), previousPosition.data());
  return Receipt::Accepted;
}

const double* LockstepAgent::neighbourPositionAtStep(const NeighbourState& s) const {
  if (s.step == step_) return s.position.data();
  if (s.step == step_ + 1) return s.previousPosition.data();
  return nullptr;
}

bool LockstepAgent::holdsNeighbourStep(int j) const {
  const NeighbourState* s = held(j);
  return s && neighbourPositionAtStep(*s) != nullptr;
}

bool LockstepAgent::neighbourState(int j, long& step, std::vector<double>& position,
                                   std::vector<double>& previousPosition) const {
  if (j < 0 || j >= scenario_->agentCount()) return false;
  const NeighbourState* held = this->held(j);
  if (board_ && j != id_ && !held) return board_->newest(j, step, position, previousPosition);
  if (!held || held->step < 0) return false;
  const NeighbourState& s = *held;
  step = s.step;
  position = s.position;
  previousPosition = s.previousPosition;
  return true;
}

bool LockstepAgent::ready() const {
  for (const NeighbourState& s : neighbours_) {
    if (!neighbourPositionAtStep(s)) return false;
  }
  return !board_ || board_->complete(step_);
}

std::vector<int> LockstepAgent::missingSensed(std::size_t limit) const {
  return board_ ? board_->missing(step_, limit) : std::vector<int>{};
}

// doc/maths.md §10, as SafetyStage::apply: after the update, from q_k and the sensed q_j^k.
void LockstepAgent::filter(double* next) {
  previousConstraintsActive_ = constraintsActive_;
  previousForeignConstraintsActive_ = foreignConstraintsActive_;
  if (!board_) return;
  board_->sensed(id_, step_, sensed_);
  const int n = scenario_->agentCount();
  // Other formations' agents within reach, after the formation's own (ids from n on, ascending).
  if (foreign_) {
    foreign_->sense(q_.data(), scenario_->safety->sensingRadius, 0.0, ForeignMargin::LastStep, 0.0, n, sensed_);
  }
  filterNextPosition(*scenario_->safety, coefficients_.timeStep, dimension_, q_.data(), next, sensed_,
                     scenario_->obstacles, safeStep_);
  constraintsActive_ = static_cast<int>(safeStep_.projection.active.size());
  foreignConstraintsActive_ = 0;
  for (int m : safeStep_.projection.active) {
    if (safeStep_.constraints[static_cast<std::size_t>(m)].source >= n) ++foreignConstraintsActive_;
  }
}

void LockstepAgent::advance() {
  if (!ready()) throw InvalidInput("advance: a neighbour's state at step " + std::to_string(step_) + " is missing");
  std::vector<double>& next = spare_;  // d doubles, no allocation per step
  if (manoeuvre_) {
    manoeuvreStep(next.data());
  } else {
    double gradient[3];
    neighbourhood_.gradient(
        q_.data(), [this](int j) { return neighbourPositionAtStep(*held(j)); }, gradient);
    variationalStep(coefficients_, start_, step_, dimension_, qPrev_.data(), q_.data(),
                    neighbourhood_.initialVelocity().data(), gradient, next.data());
  }
  filter(next.data());
  // q_{k-1} -> q_{k-2}, q_k -> q_{k-1}, next -> q_k; the old q_{k-2}'s memory becomes the spare.
  qBeforePrev_.swap(qPrev_);
  qPrev_.swap(q_);
  q_.swap(next);
  ++step_;
  advanced_ = true;
  offerOwn();
}

// doc/maths.md §9, as in ManoeuvreIntegrator::step.
void LockstepAgent::manoeuvreStep(double* next) {
  const ManoeuvreGains g = manoeuvre_->updateGains(step_);
  double gradient[3], offset[3] = {0.0, 0.0, 0.0};
  neighbourhood_.forcedGradient(
      q_.data(), [this](int j) { return neighbourPositionAtStep(*held(j)); }, g.scaleSquared, g.rotates, gradient,
      offset);
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
  constraintsActive_ = 0;
  foreignConstraintsActive_ = 0;
  offerOwn();
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
  constraintsActive_ = previousConstraintsActive_;
  foreignConstraintsActive_ = previousForeignConstraintsActive_;
}

}  // namespace vf
