#include "variational_formation_core/agents/sensing_board.hpp"

#include <cmath>
#include <string>

#include "variational_formation_core/common/invalid_input.hpp"

namespace vf {

SensingBoard::SensingBoard(int agentCount, int dimension, double sensingRadius)
    : dimension_(dimension), sensingRadius_(sensingRadius) {
  if (agentCount < 1) throw InvalidInput("sensing: agent count must be >= 1, got " + std::to_string(agentCount));
  if (dimension != 2 && dimension != 3) throw InvalidInput("sensing: dimension must be 2 or 3, got " + std::to_string(dimension));
  if (!(sensingRadius > 0.0)) throw InvalidInput("sensing: sensing radius must be > 0");
  held_.resize(static_cast<std::size_t>(agentCount));
  agentsAtStep_[-1] = agentCount;  // nothing heard yet
  positions_ = Positions::Zero(dimension, agentCount);
}

SensingBoard::Offer SensingBoard::offer(long sender, long step, const double* position, const double* previousPosition) {
  if (sender < 0 || sender >= agentCount()) return Offer::UnknownSender;
  for (int a = 0; a < dimension_; ++a) {
    if (!std::isfinite(position[a]) || !std::isfinite(previousPosition[a])) return Offer::NonFinite;
  }
  std::vector<std::function<void()>> wake;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    Held& h = held_[static_cast<std::size_t>(sender)];
    if (step == h.step) return Offer::Duplicate;
    if (step < h.step || step < 0) return Offer::GoesBack;
    auto old = agentsAtStep_.find(h.step);
    if (--old->second == 0) agentsAtStep_.erase(old);
    ++agentsAtStep_[step];
    h.step = step;
    for (int a = 0; a < dimension_; ++a) {
      h.position[a] = position[a];
      h.previousPosition[a] = previousPosition[a];
    }
    for (auto w = waiting_.begin(); w != waiting_.end();) {  // a few steps at most
      if (completeLocked(w->first)) {
        for (auto& f : w->second) wake.push_back(std::move(f));
        w = waiting_.erase(w);
      } else {
        ++w;
      }
    }
  }
  for (auto& w : wake) w();  // outside the lock: a waker may offer or ask again
  return Offer::Accepted;
}

bool SensingBoard::completeLocked(long step) const {
  // Every newest state is at step (q^step itself) or step + 1 (which carries q^step).
  return agentsAtStep_.begin()->first >= step && agentsAtStep_.rbegin()->first <= step + 1;
}

bool SensingBoard::complete(long step) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return completeLocked(step);
}

const double* SensingBoard::positionAt(const Held& h, long step) const {
  if (h.step == step) return h.position;
  if (h.step == step + 1) return h.previousPosition;
  return nullptr;
}

bool SensingBoard::sensed(int i, long step, std::vector<SensedAgent>& out) {
  out.clear();
  std::lock_guard<std::mutex> lock(mutex_);
  if (i < 0 || i >= agentCount() || !completeLocked(step)) return false;
  if (listedStep_ != step) {
    // Once per step for every agent that shares the board: the same grid and lists as
    // SafetyStage::apply over the same positions, hence the same sensed sets.
    for (std::size_t j = 0; j < held_.size(); ++j) {
      const double* q = positionAt(held_[j], step);
      for (int a = 0; a < dimension_; ++a) positions_(a, static_cast<Eigen::Index>(j)) = q[a];
    }
    grid_.build(positions_, sensingRadius_);
    grid_.neighbourLists(positions_, sensingRadius_, start_, ids_);
    listedStep_ = step;
  }
  for (int k = start_[static_cast<std::size_t>(i)]; k < start_[static_cast<std::size_t>(i) + 1]; ++k) {
    SensedAgent s;
    s.id = ids_[static_cast<std::size_t>(k)];
    for (int a = 0; a < dimension_; ++a) s.position[a] = positions_(a, s.id);
    out.push_back(s);
  }
  return true;
}

std::vector<int> SensingBoard::missing(long step, std::size_t limit) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<int> out;
  for (std::size_t j = 0; j < held_.size() && out.size() < limit; ++j) {
    if (!positionAt(held_[j], step)) out.push_back(static_cast<int>(j));
  }
  return out;
}

bool SensingBoard::newest(int j, long& step, std::vector<double>& position, std::vector<double>& previousPosition) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (j < 0 || j >= agentCount() || held_[static_cast<std::size_t>(j)].step < 0) return false;
  const Held& h = held_[static_cast<std::size_t>(j)];
  step = h.step;
  position.assign(h.position, h.position + dimension_);
  previousPosition.assign(h.previousPosition, h.previousPosition + dimension_);
  return true;
}

bool SensingBoard::whenComplete(long step, std::function<void()> wake) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (completeLocked(step)) return false;
  waiting_[step].push_back(std::move(wake));
  return true;
}

}  // namespace vf
