#pragma once

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "variational_formation_core/agents/formation_monitor.hpp"
#include "variational_formation_core/protocol/referee_ready.hpp"

namespace vf::protocol {

/**
 * The referee of a timed run (doc/robots.md) without a transport: the agents do not wait for
 * each other, so it keeps each agent's newest state and, on every tick of its own clock, measures
 * them all as one step (its step count is the tick's). The run starts once every agent's first
 * state is there and ends once every agent reached the scenario's last step. A respawned agent
 * may restart from a lower step once its old state is `staleAfter` seconds old.
 *
 * Each tick and each failure goes to step(), which returns a RefereeReady: what to do, in order.
 * - Start by identity: the first progress goes out at the first tick that measured every agent
 *   (and once a viewer listens, if one is awaited); it lets the agents go.
 * - Throttling: after that the agents ignore the window, and a progress says every quarter window
 *   (at least every tick) how far the run is.
 * - The end: the tick that reaches the scenario's last step, or at which every agent reached it,
 *   finishes the run; a failure (step(Failure)) or a blocked formation (step(Blocked)) ends it.
 *
 * State is the caller's message type with fields step, position and previous_position; times
 * are the caller's clock in seconds.
 */
template <class State>
class TimedReferee {
 public:
  /// @param staleAfter [s] (see above); @param window ~window (>= 1, the progress period is a
  /// quarter of it); @param waitForViewer ~wait_for_viewer.
  TimedReferee(const Scenario& scenario, double staleAfter, long window = 100, bool waitForViewer = false)
      : monitor_(std::make_unique<FormationMonitor>(scenario)),
        staleAfter_(staleAfter),
        window_(window),
        waitForViewer_(waitForViewer),
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
  using Ready = RefereeReady;
  /// The status clock ticks at `now` [s]; `viewer`: one listens on the markers (if one is
  /// awaited); `lastCommandStep`: the stamp of the newest issued command (-1: none).
  struct Tick {
    double now;
    bool viewer;
    long lastCommandStep;
  };
  /// Measures the tick (tick()), then: a pending command goes out at once (commandStep), and the
  /// progress and the end as the class comment says. Nothing after the end.
  Ready step(const Tick& e) {
    Ready r;
    if (ended()) return r;
    r.publish = tick(e.now);
    if (r.publish.empty()) return r;  // not every agent is there yet: the run has not started
    convergedStep_ = r.publish.back().converged ? r.publish.back().convergedStep : -1;
    r.commandsAt = commandStep(e.lastCommandStep);
    const long completed = completedStep(), last = monitor_->scenario().steps;
    if (last > 0 && completed >= last) return finishInto(r);
    const bool starts = progress_.state == Progress::State::Waiting;
    if (starts ? (e.viewer || !waitForViewer_) : completed >= progress_.completedStep + std::max<long>(1, window_ / 4)) {
      progress_.state = Progress::State::Running;
      progress_.completedStep = completed;
      progress_.allowedStep = last > 0 ? std::min(completed + window_, last) : completed + window_;
      progress_.convergedStep = convergedStep_;
      r.progress = true;
      r.starts = starts;
    }
    return finished_ ? finishInto(r) : r;
  }
  Ready step(const Failure& e) { return endRun(progress_, Progress::State::Failed, e.reason); }
  Ready step(const Blocked&) { return endRun(progress_, Progress::State::Finished, ""); }
  /// The stamp of a command issued now: after the latest tick and after the newest issued command
  /// (`lastCommandStep`, -1: none); the agents take the newest.
  long commandStep(long lastCommandStep) const { return std::max(completedStep() + 1, lastCommandStep + 1); }
  /// The progress as published last (Waiting before the start), or the end.
  const Progress& progressNow() const { return progress_; }
  bool ended() const { return over(progress_); }

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
  Ready& finishInto(Ready& r) {
    r.finish = endRun(progress_, Progress::State::Finished, "").finish;
    return r;
  }

  std::unique_ptr<FormationMonitor> monitor_;
  double staleAfter_;
  long window_;
  bool waitForViewer_;
  Progress progress_;
  long convergedStep_ = -1;  // first step of the congruent stretch at the latest tick (-1: none)
  std::vector<State> newest_;
  std::vector<double> receivedAt_;
  std::vector<bool> held_;
  long tick_ = -1;
  double dataAge_ = 0.0;
  bool finished_ = false;
};

}  // namespace vf::protocol
