#include "variational_formation_core/safety/safety_stage.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace vf {

SafetyStage::SafetyStage(const SafetySettings& settings, std::vector<Obstacle> obstacles, double timeStep)
    : settings_(settings), obstacles_(std::move(obstacles)), timeStep_(timeStep) {}

void SafetyStage::sense(const Positions& q, long step) {
  if (sensedStep_ == step) return;
  sensedStep_ = step;
  grid_.build(q, settings_.sensingRadius);
  grid_.neighbourLists(q, settings_.sensingRadius, sensedStart_, sensedIds_);
}

ClosestPair SafetyStage::closestPair(const Positions& q, long step) {
  sense(q, step);
  const ClosestPair best = closestListed(q, settings_.sensingRadius, sensedStart_, sensedIds_);
  if (best.first < 0) return vf::closestPair(q, 2.0 * settings_.sensingRadius);  // nobody within R
  return best;
}

void SafetyStage::apply(const Positions& q, long step, Positions& qNext) {
  sense(q, step);
  const int d = static_cast<int>(q.rows());
  bindingAgents_.clear();
  bindingObstacles_.clear();
  speedLimited_ = 0;
  for (int i = 0; i < q.cols(); ++i) {
    scratch_.clear();
    for (int k = sensedStart_[static_cast<std::size_t>(i)]; k < sensedStart_[static_cast<std::size_t>(i) + 1]; ++k) {
      SensedAgent a;
      a.id = sensedIds_[static_cast<std::size_t>(k)];
      for (int c = 0; c < d; ++c) a.position[c] = q(c, a.id);
      scratch_.push_back(a);
    }
    SafeStep& s = step_;
    filterNextPosition(settings_, timeStep_, d, q.col(i).data(), qNext.col(i).data(), scratch_, obstacles_, s);
    if (s.projection.speedLimited) ++speedLimited_;
    if (!s.projection.active.empty()) bindingAgents_.push_back(i);
    for (int m : s.projection.active) {
      const int source = s.constraints[static_cast<std::size_t>(m)].source;
      if (source >= 0) {
        bindingAgents_.push_back(source);
      } else {
        bindingObstacles_.push_back(-1 - source);
      }
    }
  }
  for (std::vector<int>* v : {&bindingAgents_, &bindingObstacles_}) {
    std::sort(v->begin(), v->end());
    v->erase(std::unique(v->begin(), v->end()), v->end());
  }
}

}  // namespace vf
