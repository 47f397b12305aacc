#include "variational_formation_core/safety/timed_safety.hpp"

#include <algorithm>
#include <cmath>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/model/validation.hpp"

namespace vf {

double stalenessMargin(double age, double maxSpeed) { return std::max(0.0, age) * maxSpeed; }

double timedSafetySpeed(const SafetySettings& settings, double robotDefault) {
  if (std::isfinite(settings.maxSpeed)) return settings.maxSpeed;
  if (std::isfinite(robotDefault) && robotDefault > 0.0) return robotDefault;
  throw InvalidInput("safety.max_speed: timed mode needs it: an agent widens r by the distance another can have "
                     "covered since its newest state was sent, age x max_speed (doc/robots.md, \"Safety\")");
}

TimedSafety::TimedSafety(const Scenario& scenario, int id, double maxSpeed, double handOffset)
    : settings_(*scenario.safety),
      obstacles_(scenario.obstacles),
      maxSpeed_(maxSpeed),
      timeStep_(scenario.timeStep),
      dimension_(scenario.dimension),
      id_(id),
      held_(static_cast<std::size_t>(scenario.agentCount())) {
  requireFiniteAbove("safety.max_speed", maxSpeed, 0.0, "m/s");
  requireFiniteAtLeast("hand_offset", handOffset, 0.0, "m");
  // Hand points at least r + 2l apart keep axles (the bodies' centres) at least r apart.
  settings_.radius += 2.0 * handOffset;
  settings_.sensingRadius += 2.0 * handOffset;
  settings_.maxSpeed = maxSpeed;
}

bool TimedSafety::hold(int j, const double* position, double sentAt) {
  if (j < 0 || j >= static_cast<int>(held_.size()) || j == id_) return false;
  Held& h = held_[static_cast<std::size_t>(j)];
  if (h.heard && !(sentAt > h.sentAt)) return false;
  h.heard = true;
  h.sentAt = sentAt;
  std::copy(position, position + dimension_, h.position);
  return true;
}

std::vector<int> TimedSafety::unheard() const {
  std::vector<int> ids;
  for (int j = 0; j < static_cast<int>(held_.size()); ++j) {
    if (j != id_ && !held_[static_cast<std::size_t>(j)].heard) ids.push_back(j);
  }
  return ids;
}

const SafeStep& TimedSafety::filter(double now, const double* q, double* qNext) {
  sensed_.clear();
  for (int j = 0; j < static_cast<int>(held_.size()); ++j) {
    const Held& h = held_[static_cast<std::size_t>(j)];
    if (!h.heard) continue;  // only while the agent holds anyway (unheard())
    SensedAgent s;
    s.id = j;
    std::copy(h.position, h.position + dimension_, s.position);
    s.margin = stalenessMargin(now - h.sentAt, maxSpeed_);
    sensed_.push_back(s);
  }
  const int n = static_cast<int>(held_.size());
  if (foreign_) foreign_->sense(q, settings_.sensingRadius, now, ForeignMargin::Age, maxSpeed_, n, sensed_);
  filterNextPosition(settings_, timeStep_, dimension_, q, qNext, sensed_, obstacles_, step_);
  return step_;
}

int TimedSafety::constraintsActive() const {
  return static_cast<int>(step_.projection.active.size()) + (step_.projection.speedLimited ? 1 : 0);
}

int TimedSafety::foreignConstraintsActive() const {
  int count = 0;
  for (int m : step_.projection.active) {
    if (step_.constraints[static_cast<std::size_t>(m)].source >= static_cast<int>(held_.size())) ++count;
  }
  return count;
}

}  // namespace vf
