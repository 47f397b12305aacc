#include "variational_formation_core/safety/safety_watch.hpp"

#include <sstream>

#include "variational_formation_core/common/number_checks.hpp"

namespace vf {

namespace {
const std::vector<int> kNone;

double checkedBlockedAfter(double seconds) {
  requireFiniteAbove("blocked_after", seconds, 0.0, "s");
  return seconds;
}
}  // namespace

SafetyWatch::SafetyWatch(const Scenario& scenario, double blockedAfter, bool timed)
    : agents_(scenario.agentCount()),
      hint_(scenario.safety ? scenario.safety->sensingRadius : 1.0),
      timed_(timed),
      blocked_(checkedBlockedAfter(blockedAfter), scenario.timeStep),
      newest_(static_cast<std::size_t>(timed ? agents_ : 0), 0),
      newestStep_(static_cast<std::size_t>(timed ? agents_ : 0), -1) {}

void SafetyWatch::note(int agent, long step, long constraintsActive) {
  if (agent < 0 || agent >= agents_) return;
  const std::size_t i = static_cast<std::size_t>(agent);
  if (timed_) {
    if (step < newestStep_[i]) return;  // the referee measures the newest state
    newestStep_[i] = step;
    newest_[i] = constraintsActive;
    return;
  }
  std::vector<long>& at = byStep_[step];
  at.resize(static_cast<std::size_t>(agents_), 0);
  at[i] = constraintsActive;
}

bool SafetyWatch::observe(long step, const Positions& q, double error, bool congruent) {
  last_ = closestPair(q, hint_);
  if (closestStep_ < 0 || last_.distance < closest_.distance) {
    closest_ = last_;
    closestStep_ = step;
  }
  const std::vector<long>* values = &newest_;
  if (!timed_) {
    const auto it = byStep_.find(step);
    values = it == byStep_.end() ? nullptr : &it->second;
  }
  active_ = 0;
  binding_.clear();
  if (values) {
    for (std::size_t i = 0; i < values->size(); ++i) {
      active_ += (*values)[i];
      if ((*values)[i] > 0) binding_.push_back(static_cast<int>(i));
    }
  }
  if (!timed_) byStep_.erase(byStep_.begin(), byStep_.upper_bound(step));  // measured: never needed again
  if (active_ > 0) ++filterActiveSteps_;
  return blocked_.update(step, error, congruent, binding_, kNone);
}

std::string SafetyWatch::resultLines() const {
  std::ostringstream out;
  out << "closest_approach: ";
  if (closest_.first < 0) {
    out << "~\n";
  } else {
    out << "{distance: " << formatNumber(closest_.distance) << ", agents: [" << closest_.first << ", "
        << closest_.second << "], step: " << closestStep_ << "}\n";
  }
  out << "filter_active_steps: " << filterActiveSteps_ << "\n";
  return out.str();
}

}  // namespace vf
