#pragma once

#include <functional>
#include <map>
#include <mutex>
#include <utility>
#include <vector>

#include "variational_formation_core/safety/safety_filter.hpp"
#include "variational_formation_core/model/spatial_grid.hpp"

namespace vf {

/**
 * Who a lockstep agent senses, exactly (doc/distributed.md, "Sensing"): the newest state
 * (m, q_j^m, q_j^{m-1}) of every agent of the formation, and, for a step s whose positions it
 * holds for every agent, the agents within the sensing radius of each agent at s, from one
 * SpatialGrid per step built exactly as SafetyStage builds it. The lockstep rule with safety on
 * is a barrier: an agent computes q^{s+1} only once the board holds q_j^s of every agent j, so no
 * agent is ever more than one step ahead of another and the newest state alone always carries
 * the q_j^s asked for (no older history is needed, as for neighbours). One board per agent (a
 * node), or one per process shared by the agents of a manager (one grid per step for all of
 * them). Thread-safe.
 */
class SensingBoard {
 public:
  /// What became of an offered state.
  enum class Offer { Accepted, Duplicate, UnknownSender, NonFinite, GoesBack };

  /// @param agentCount n, @param dimension d (2 or 3), @param sensingRadius R [m] > 0.
  SensingBoard(int agentCount, int dimension, double sensingRadius);

  /// Agent `sender`'s state at `step`: q_step and q_{step-1}, d doubles each [m].
  Offer offer(long sender, long step, const double* position, const double* previousPosition);
  /// Holds q_j^step of every agent j (each newest state is at step or step + 1).
  bool complete(long step) const;
  /**
   * The agents within R of agent i at `step` (|q_i - q_j|^2 < R^2, as SafetyStage finds them),
   * ascending id, with their q_j^step.
   * @return false (and `out` empty) unless complete(step).
   */
  bool sensed(int i, long step, std::vector<SensedAgent>& out);
  /// The agents whose q^step is not held, ascending, at most `limit` of them.
  std::vector<int> missing(long step, std::size_t limit) const;
  /// The newest state held of agent j; false if none.
  bool newest(int j, long& step, std::vector<double>& position, std::vector<double>& previousPosition) const;
  /**
   * Calls `wake` once complete(step) holds, on the thread of the offer that makes it hold (so it
   * should only queue work). @return false if complete(step) holds already (`wake` is not kept).
   */
  bool whenComplete(long step, std::function<void()> wake);

  int agentCount() const { return static_cast<int>(held_.size()); }
  int dimension() const { return dimension_; }

 private:
  struct Held {
    long step = -1;
    double position[3] = {0.0, 0.0, 0.0};
    double previousPosition[3] = {0.0, 0.0, 0.0};
  };
  bool completeLocked(long step) const;
  const double* positionAt(const Held& h, long step) const;

  int dimension_;
  double sensingRadius_;
  mutable std::mutex mutex_;
  std::vector<Held> held_;             // by agent id
  std::map<long, int> agentsAtStep_;   // newest step -> how many agents hold it there
  std::map<long, std::vector<std::function<void()>>> waiting_;  // by the step they wait for
  long listedStep_ = -1;  // the step the lists below are of
  Positions positions_;
  SpatialGrid grid_;
  std::vector<int> start_, ids_;
};

}  // namespace vf
