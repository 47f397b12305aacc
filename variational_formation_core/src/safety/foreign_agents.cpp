#include "variational_formation_core/safety/foreign_agents.hpp"

#include <cmath>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/safety/timed_safety.hpp"

namespace vf {

ForeignAgents::ForeignAgents(int dimension) : dimension_(dimension) {
  if (dimension != 2 && dimension != 3) {
    throw InvalidInput("foreign agents: dimension must be 2 or 3, got " + std::to_string(dimension));
  }
}

bool ForeignAgents::hold(const std::string& name, const double* position, const double* previousPosition,
                         double heardAt) {
  double step2 = 0.0;
  for (int a = 0; a < dimension_; ++a) {
    if (!std::isfinite(position[a]) || !std::isfinite(previousPosition[a])) return false;
    step2 += (position[a] - previousPosition[a]) * (position[a] - previousPosition[a]);
  }
  if (!std::isfinite(heardAt)) return false;
  std::lock_guard<std::mutex> lock(mutex_);
  const auto found = index_.emplace(name, held_.size());
  if (found.second) {
    held_.emplace_back();
    held_.back().name = name;
  }
  Held& h = held_[found.first->second];
  for (int a = 0; a < dimension_; ++a) h.position[a] = position[a];
  h.lastStep = std::sqrt(step2);
  h.heardAt = heardAt;
  count_.store(held_.size(), std::memory_order_release);
  return true;
}

void ForeignAgents::sense(const double* q, double sensingRadius, double now, ForeignMargin rule, double maxSpeed,
                          int firstId, std::vector<SensedAgent>& out) const {
  if (size() == 0) return;  // the lockstep hot path with no other formation: nothing to lock
  std::lock_guard<std::mutex> lock(mutex_);
  for (std::size_t k = 0; k < held_.size(); ++k) {
    const Held& h = held_[k];
    const double margin = rule == ForeignMargin::Age ? stalenessMargin(now - h.heardAt, maxSpeed) : h.lastStep;
    double zz = 0.0;
    for (int a = 0; a < dimension_; ++a) zz += (q[a] - h.position[a]) * (q[a] - h.position[a]);
    const double reach = sensingRadius + margin;
    if (!(zz < reach * reach)) continue;  // safetyConstraints would skip it too
    SensedAgent s;
    s.id = firstId + static_cast<int>(k);
    for (int a = 0; a < dimension_; ++a) s.position[a] = h.position[a];
    s.margin = margin;
    s.reciprocates = false;
    out.push_back(s);
  }
}

std::string ForeignAgents::name(int index) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return index >= 0 && static_cast<std::size_t>(index) < held_.size() ? held_[static_cast<std::size_t>(index)].name
                                                                       : std::string();
}

ClosestForeign ForeignAgents::closest(const Positions& q) const {
  ClosestForeign best;
  if (size() == 0 || q.rows() != dimension_) return best;
  std::lock_guard<std::mutex> lock(mutex_);
  for (const Held& h : held_) {
    for (int i = 0; i < q.cols(); ++i) {
      double zz = 0.0;
      for (int a = 0; a < dimension_; ++a) zz += (q(a, i) - h.position[a]) * (q(a, i) - h.position[a]);
      const double distance = std::sqrt(zz);
      if (distance < best.distance) {
        best.distance = distance;
        best.agent = i;
        best.foreign = h.name;
      }
    }
  }
  return best;
}

}  // namespace vf
