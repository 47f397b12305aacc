#include "variational_formation/ros/trails.hpp"

#include <algorithm>

namespace vf {

Trails::Trails(int agents, int length)
    : trails_(static_cast<std::size_t>(agents)),
      stride_(static_cast<int>(std::clamp((static_cast<long>(agents) * length + kPoints - 1) / kPoints, 1L,
                                          std::max(1L, static_cast<long>(length) / 2)))),
      // Enough kept positions that the trail, with the current position, spans `length` steps.
      kept_(static_cast<std::size_t>(std::max(1, length / stride_))) {}

void Trails::add(long step, const Positions& q) {
  if (step % stride_ != 0) return;
  for (std::size_t i = 0; i < trails_.size(); ++i) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    p.head(q.rows()) = q.col(static_cast<Eigen::Index>(i));
    trails_[i].push_back(p);
    if (trails_[i].size() > kept_) trails_[i].pop_front();
  }
}

}  // namespace vf
