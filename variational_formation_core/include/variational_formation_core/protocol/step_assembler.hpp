#pragma once

#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "variational_formation_core/common/invalid_input.hpp"

namespace vf::protocol {

/// The step k of a message stamped with simulated time t_k = k h [s].
inline long stepOfStamp(double seconds, double timeStep) { return std::lround(seconds / timeStep); }

/**
 * Holds the parts of each step (every agent's state, the status, and the markers where a step has
 * them) until the step is whole, and hands out whole steps in step order only: a bag written from
 * it is in time order, which Python's rosbag assumes when it merges chunks (doc/distributed.md,
 * recording). Parts of a handed-out step, and repeats of a held part, are refused: the first copy
 * counts. Transport-free: State, Status and Markers are whatever the caller stores (message
 * pointers in the recorder).
 */
template <class State, class Status, class Markers>
class StepAssembler {
 public:
  struct Step {
    long step = -1;
    std::vector<State> states;  ///< agent i's state at index i
    Status status{};
    Markers markers{};
    bool hasMarkers = false;
  };

  /// @param needsMarkers whether step k is whole only with its markers.
  StepAssembler(int agents, std::function<bool(long)> needsMarkers)
      : agents_(agents), needsMarkers_(std::move(needsMarkers)) {
    if (agents < 1) throw InvalidInput("step assembler: needs at least one agent, got " + std::to_string(agents));
  }

  /// @return false if refused (a step already handed out, or this part already held).
  bool addState(int agent, long step, State state) {
    if (agent < 0 || agent >= agents_ || step <= handedOut_) return false;
    Pending& p = pendingAt(step);
    if (p.seen[static_cast<std::size_t>(agent)]) return false;
    p.seen[static_cast<std::size_t>(agent)] = true;
    p.step.states[static_cast<std::size_t>(agent)] = std::move(state);
    ++p.stateCount;
    return true;
  }
  bool addStatus(long step, Status status) {
    if (step <= handedOut_) return false;
    Pending& p = pendingAt(step);
    if (p.hasStatus) return false;
    p.hasStatus = true;
    p.step.status = std::move(status);
    return true;
  }
  /// Markers of a step that needs none are refused.
  bool addMarkers(long step, Markers markers) {
    if (step <= handedOut_ || !needsMarkers_(step)) return false;
    Pending& p = pendingAt(step);
    if (p.step.hasMarkers) return false;
    p.step.hasMarkers = true;
    p.step.markers = std::move(markers);
    return true;
  }
  /**
   * The whole steps that follow the last handed-out one, in order, each handed out once.
   * @param mayHandOut what else a whole step waits for (the recorder: the commands its status
   * counts); none if empty. The first whole step it holds back stops the hand-out there.
   */
  std::vector<Step> takeWhole(const std::function<bool(const Step&)>& mayHandOut = {}) {
    std::vector<Step> whole;
    while (!pending_.empty() && pending_.begin()->first == handedOut_ + 1) {
      Pending& p = pending_.begin()->second;
      const long step = pending_.begin()->first;
      if (p.stateCount < agents_ || !p.hasStatus || (needsMarkers_(step) && !p.step.hasMarkers)) break;
      if (mayHandOut && !mayHandOut(p.step)) break;
      whole.push_back(std::move(p.step));
      pending_.erase(pending_.begin());
      handedOut_ = step;
    }
    return whole;
  }
  /// Every step up to this one was handed out (-1: none).
  long handedOutThrough() const { return handedOut_; }
  /// Steps with some part held, waiting to be whole (how far a recorder is behind).
  std::size_t pendingSteps() const { return pending_.size(); }
  /// What the oldest unfinished step lacks, e.g. "step 7: agent 2's state, the status" ("" if none is held).
  std::string lacking() const {
    const long step = handedOut_ + 1;
    const auto it = pending_.find(step);
    std::string s;
    const auto add = [&s](const std::string& part) { s += (s.empty() ? "" : ", ") + part; };
    for (int i = 0; i < agents_; ++i) {
      if (it == pending_.end() || !it->second.seen[static_cast<std::size_t>(i)]) {
        add("agent " + std::to_string(i) + "'s state");
      }
    }
    if (it == pending_.end() || !it->second.hasStatus) add("the status");
    if (needsMarkers_(step) && (it == pending_.end() || !it->second.step.hasMarkers)) add("the markers");
    return "step " + std::to_string(step) + ": " + s;
  }

 private:
  struct Pending {
    Step step;
    std::vector<bool> seen;
    int stateCount = 0;
    bool hasStatus = false;
  };
  Pending& pendingAt(long step) {
    auto it = pending_.find(step);
    if (it == pending_.end()) {
      it = pending_.emplace(step, Pending()).first;
      it->second.step.step = step;
      it->second.step.states.resize(static_cast<std::size_t>(agents_));
      it->second.seen.assign(static_cast<std::size_t>(agents_), false);
    }
    return it->second;
  }

  int agents_;
  std::function<bool(long)> needsMarkers_;
  std::map<long, Pending> pending_;
  long handedOut_ = -1;
};

}  // namespace vf::protocol
