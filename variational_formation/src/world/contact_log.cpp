#include "variational_formation/world/contact_log.hpp"

#include <algorithm>

#include "variational_formation_core/common/number_checks.hpp"

namespace vf {

std::string ContactLog::participantName(int id) const {
  return id < robots_ ? "robot_" + std::to_string(id) : "obstacle_" + std::to_string(id - robots_);
}

std::vector<ContactEvent> ContactLog::record(double time, const std::vector<Touch>& touching) {
  std::vector<ContactEvent> began;
  active_ = 0;
  for (const Touch& t : touching) {
    const std::pair<int, int> pair = std::minmax(t.a, t.b);
    maxPenetration_ = std::max(maxPenetration_, t.penetration);
    maxNormalForce_ = std::max(maxNormalForce_, t.normalForce);
    const auto last = lastTouched_.find(pair);
    if (last != lastTouched_.end() && last->second == time) continue;  // listed twice
    ++active_;
    // Bodies pressed together lose and regain touch from step to step: one contact until apart.
    if (last == lastTouched_.end() || time - last->second > kSeparation) {
      began.push_back({time, participantName(pair.first), participantName(pair.second), t.normalForce, t.x, t.y});
    }
    lastTouched_[pair] = time;
  }
  count_ += static_cast<long>(began.size());
  if (!first_ && !began.empty()) first_ = began.front();
  events_.insert(events_.end(), began.begin(), began.end());
  return began;
}

std::string ContactLog::resultLines() const {
  std::string lines = "contacts: " + std::to_string(count_) + "\nfirst_contact: ";
  if (!first_) return lines + "~\n";
  return lines + "\"t = " + formatNumber(first_->time) + " s, " + first_->first + " and " + first_->second + "\"\n";
}

}  // namespace vf
