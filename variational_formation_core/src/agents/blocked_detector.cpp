#include "variational_formation_core/agents/blocked_detector.hpp"

#include <cmath>

namespace vf {

BlockedDetector::BlockedDetector(double blockedAfter, double timeStep)
    : window_(static_cast<long>(std::ceil(blockedAfter / timeStep - 1e-9))) {}

bool BlockedDetector::update(long step, double error, bool congruent, const std::vector<int>& bindingAgents,
                             const std::vector<int>& bindingObstacles) {
  if (blocked_) return true;
  // A formation in shape is not blocked; a new fall of the error restarts the clock.
  if (congruent || progressStep_ < 0 || error < (1.0 - kProgress) * reference_) {
    reference_ = error;
    progressStep_ = step;
    return false;
  }
  if (bindingAgents.empty() || step - progressStep_ < window_) return false;
  blocked_ = true;
  agents_ = bindingAgents;
  obstacles_ = bindingObstacles;
  return true;
}

std::string BlockedDetector::description() const {
  const auto list = [](const std::vector<int>& ids) {
    std::string s;
    for (std::size_t k = 0; k < ids.size(); ++k) s += (k ? ", " : "") + std::to_string(ids[k]);
    return s;
  };
  std::string text = "blocked: agents " + list(agents_);
  if (!obstacles_.empty()) text += "; obstacles " + list(obstacles_);
  return text;
}

}  // namespace vf
