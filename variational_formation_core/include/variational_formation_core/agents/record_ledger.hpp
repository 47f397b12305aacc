#pragma once

#include <array>
#include <set>
#include <vector>

namespace vf {

/// Steps of one stream seen so far: all below `next`, and some beyond it (out of order).
struct StepSet {
  long next = 0;
  std::set<long> ahead;
  /// Adds a step. @return true if it is new.
  bool add(long step);
  bool holds(long step) const;
};

/**
 * What a recorder has written of a run, so that a bag holds each (agent, step) state exactly
 * once (doc/distributed.md, recording). A state can reach the recorder twice: from the agent's
 * topic and from a history it fetched, or from an agent that republishes after a restart. The
 * first copy is written; a later one is compared with it, bit for bit, while the ledger still
 * keeps it (the `keep` newest steps of each agent): recovery must reproduce a step exactly, so a
 * repeat that differs means the run is wrong.
 */
class RecordLedger {
 public:
  enum class Arrival {
    New,        ///< first copy: write it
    Identical,  ///< a repeat, equal bit for bit to the first copy
    Unchecked,  ///< a repeat of a step older than the kept ones
    Differs,    ///< a repeat that differs from the first copy
  };

  /// @param agents n. @param keep how many of each agent's newest steps are kept for comparison.
  RecordLedger(int agents, long keep);

  /**
   * A state of agent i at step k: q_k and q_{k-1}, dimension 2 or 3.
   * @return whether it is new, and if not, how it compares with the first copy.
   */
  Arrival addState(int agent, long step, const std::vector<double>& position,
                   const std::vector<double>& previousPosition);
  /// All states of agent i below this step have arrived.
  long statesBelow(int agent) const { return agents_[static_cast<std::size_t>(agent)].steps.next; }
  bool holdsState(int agent, long step) const { return agents_[static_cast<std::size_t>(agent)].steps.holds(step); }
  int agentCount() const { return static_cast<int>(agents_.size()); }

 private:
  using Coordinates = std::array<double, 6>;  // q_k then q_{k-1}, 3 values each
  struct Kept {
    long step = -1;
    Coordinates coordinates{};
  };
  struct AgentLedger {
    StepSet steps;
    std::vector<Kept> kept;  // a ring: step k in slot k mod keep
    long newest = -1;
  };
  std::vector<AgentLedger> agents_;
  long keep_;
};

}  // namespace vf
