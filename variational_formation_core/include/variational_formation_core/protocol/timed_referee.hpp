#pragma once

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "variational_formation_core/agents/formation_monitor.hpp"

namespace vf::protocol {

/**
 * The referee of a timed run (doc/robots.md) without a transport: the agents do not wait for
 * each other, so it keeps each agent's newest state and, on every tick of its own clock, measures
 * them all as one step (its step count is the tick's). The run starts once every agent's first
 * state is there and ends once every agent reached the scenario's last step. A respawned agent
 * may restart from a lower step once its old state is `staleAfter` seconds old.
 *
 * State is the caller's message type with fields step, position and previous_position; times
 * are the caller's clock in seconds.
 */
template <class State>
class TimedReferee {
 public:
  TimedReferee(const Scenario& scenario, double staleAfter)
      : monitor_(std::make_unique<FormationMonitor>(scenario)),
        staleAfter_(staleAfter),
        newest_(static_cast<std::size_t>(scenario.agentCount())),
        receivedAt_(static_cast<std::size_t>(scenario.agentCount()), 0.0),
        held_(static_cast<std::size_t>(scenario.agentCount()), false) {}

  /// A state of `agent` received at `now`. @return false (why says why) if it has the wrong
  /// dimension or a non-finite value.
  bool offerState(int agent, const State& s, double now, std::string& why) {
    const std::size_t d = static_cast<std::size_t>(monitor_->scenario().dimension);
    bool finite = s.position.size() == d && s.previous_position.size() == d;
    for (std::size_t a = 0; finite && a < d; ++a) finite = std::isfinite(s.position[a]) && std::isfinite(s.previous_position[a]);
    if (!finite) {
      why = "(step " + std::to_string(s.step) + "): wrong dimension or not finite";
      return false;
    }
    const std::size_t i = static_cast<std::size_t>(agent);
    if (!held_[i] || s.step > newest_[i].step || now - receivedAt_[i] > staleAfter_) {
      newest_[i] = s;
      receivedAt_[i] = now;
      held_[i] = true;
    }
    return true;
  }
  /**
   * A tick of the status clock at `now`: measures every agent's newest state as step tick().
   * @return the snapshot to publish; none before every agent was heard or after the end.
   */
  std::vector<FormationSnapshot> tick(double now) {
    if (finished_ || std::find(held_.begin(), held_.end(), false) != held_.end()) return {};
    ++tick_;
    dataAge_ = 0.0;
    bool allDone = monitor_->scenario().steps > 0;
    for (std::size_t i = 0; i < newest_.size(); ++i) {
      const State& s = newest_[i];
      dataAge_ = std::max(dataAge_, now - receivedAt_[i]);
      allDone = allDone && s.step >= monitor_->scenario().steps;
      monitor_->add(static_cast<long>(i), tick_, s.position, s.previous_position, tick_);
    }
    finished_ = allDone;
    return monitor_->takeCompleted();
  }
  /// Every agent reached the last step (at the latest tick).
  bool finished() const { return finished_; }
  /// Agents heard before whose newest state is older than staleAfter at `now` (dead or stopped?).
  std::vector<int> silent(double now) const {
    std::vector<int> ids;
    for (std::size_t i = 0; i < newest_.size(); ++i) {
      if (held_[i] && now - receivedAt_[i] >= staleAfter_) ids.push_back(static_cast<int>(i));
    }
    return ids;
  }
  /// Agents not heard yet.
  std::vector<int> unheard() const {
    std::vector<int> ids;
    for (std::size_t i = 0; i < held_.size(); ++i) {
      if (!held_[i]) ids.push_back(static_cast<int>(i));
    }
    return ids;
  }
  const State* newest(int agent) const {
    return held_[static_cast<std::size_t>(agent)] ? &newest_[static_cast<std::size_t>(agent)] : nullptr;
  }
  bool started() const { return tick_ >= 0; }
  long completedStep() const { return monitor_->nextStep() - 1; }
  /// Age [s] of the oldest state the latest tick used.
  double dataAge() const { return dataAge_; }
  const FormationMonitor& monitor() const { return *monitor_; }
  /// The commands the agents apply, for the steps measured from now on (FormationMonitor::setSchedule).
  void setSchedule(const CommandSchedule& schedule) { monitor_->setSchedule(schedule); }

 private:
  std::unique_ptr<FormationMonitor> monitor_;
  double staleAfter_;
  std::vector<State> newest_;
  std::vector<double> receivedAt_;
  std::vector<bool> held_;
  long tick_ = -1;
  double dataAge_ = 0.0;
  bool finished_ = false;
};

}  // namespace vf::protocol
