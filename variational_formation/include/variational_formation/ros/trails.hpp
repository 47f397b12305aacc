#pragma once

#include <deque>
#include <vector>

#include <Eigen/Dense>

#include "variational_formation_core/common/types.hpp"

namespace vf {

/**
 * The agents' recent positions, for the trail markers. A trail spans the last `length` steps;
 * in a formation of more than a few agents it holds a position every `stride` steps only, so that
 * all trails together hold at most kPoints positions (or two per agent, the fewest that still
 * draw a bend), however many agents there are: a marker array of 1000 agents with 100 positions
 * each was 3 MB a step, and recording it cost most of the run's time (doc/benchmarks.md,
 * "Recording and pacing").
 */
class Trails {
 public:
  /// Positions held over all trails, at most, beyond two per agent (up to 6 agents at the
  /// default length 100 keep every step).
  static constexpr long kPoints = 600;

  /// @param agents n (>= 1). @param length the steps a trail spans (>= 2).
  Trails(int agents, int length);
  /// Step k's positions (a column per agent, 2 or 3 rows): kept if k is a multiple of stride().
  void add(long step, const Positions& q);
  /// Steps between two kept positions: ceil(n length / kPoints), within [1, length / 2].
  int stride() const { return stride_; }
  int agents() const { return static_cast<int>(trails_.size()); }
  /// Agent i's kept positions, oldest first (in 3D: z = 0 on the plane).
  const std::deque<Eigen::Vector3d>& of(int agent) const { return trails_[static_cast<std::size_t>(agent)]; }

 private:
  std::vector<std::deque<Eigen::Vector3d>> trails_;
  int stride_ = 1;
  std::size_t kept_ = 2;  // positions per trail
};

}  // namespace vf
