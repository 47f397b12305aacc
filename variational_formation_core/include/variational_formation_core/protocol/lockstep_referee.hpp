#pragma once

#include <algorithm>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/agents/formation_monitor.hpp"
#include "variational_formation_core/protocol/progress.hpp"
#include "variational_formation_core/protocol/recovery.hpp"
#include "variational_formation_core/protocol/referee_ready.hpp"

namespace vf::protocol {

namespace detail {
/// The message a held state is: the state itself, or what a pointer to it points to.
template <class S>
auto heldMessage(const S& s, int) -> decltype(*s) {
  return *s;
}
template <class S>
const S& heldMessage(const S& s, long) {
  return s;
}
}  // namespace detail

/**
 * The referee of a lockstep run without a transport (doc/distributed.md): the monitor's side of
 * the protocol. It takes events (a state from an agent or from a history, the recorder's
 * progress, a participant's failure, a tick that may see a viewer) and says what to do: the
 * completed steps to publish, the progress to publish, whether the run finished or failed, which
 * agents to catch up from, and what it waits for. The events that change the run's course go to
 * step(), which returns a RefereeReady: what to do, in order.
 *
 * - Start by identity: the run starts once every agent's step 0 is complete (and recorded, and
 *   watched by a viewer if one is awaited).
 * - Flow window: agents may run `window` steps past what it and the recorder completed; a
 *   progress goes out on every change of state, every quarter window, and whenever the agents
 *   may already wait at the allowed step (the throttling deadlock, see the tests).
 * - Recorder gate: accepted states and published steps are kept until the recorder confirms
 *   them, to be served again (`~history`) or republished.
 * - Restart: resume() goes on from the newest progress any agent heard.
 * - Failures: every end of the run is its decision (step(Failure), step(Blocked), the recorder's
 *   failure, the last step); the node finishes only when a Ready says so.
 *
 * State is the caller's message type with fields step, position and previous_position, or a
 * shared pointer to one (the monitor holds its states by pointer into the batches they came in,
 * not as copies); Published is what it publishes per completed step (kept for the recorder).
 */
template <class State, class Published>
class LockstepReferee {
 public:
  /// @param window ~window (>= 1); @param recording a recorder takes part; @param waitForViewer ~wait_for_viewer.
  LockstepReferee(const Scenario& scenario, long window, bool recording, bool waitForViewer)
      : monitor_(std::make_unique<FormationMonitor>(scenario)),
        window_(window),
        recording_(recording),
        waitForViewer_(waitForViewer),
        newest_(static_cast<std::size_t>(scenario.agentCount())),
        held_(static_cast<std::size_t>(scenario.agentCount()), false),
        unrecordedStates_(static_cast<std::size_t>(scenario.agentCount())) {
    if (window < 1) throw InvalidInput("~window: must be >= 1, got " + std::to_string(window));
  }

  /// A state of `agent` (from its topic, or `fromHistory`). Validated by FormationMonitor::add.
  FormationMonitor::Receipt offerState(int agent, const State& s, bool fromHistory = false) {
    const auto& m = message(s);
    const auto receipt = monitor_->add(agent, m.step, m.position, m.previous_position, acceptUpTo_);
    const bool accepted = receipt == FormationMonitor::Receipt::Accepted;
    if (accepted || (!fromHistory && receipt == FormationMonitor::Receipt::Duplicate)) {
      const std::size_t i = static_cast<std::size_t>(agent);
      if (!held_[i] || m.step > message(newest_[i]).step) {
        newest_[i] = s;
        held_[i] = true;
      }
      if (recording_ && accepted) unrecordedStates_[i].push_back(s);
    }
    return receipt;
  }
  void offerHistory(int agent, const std::vector<State>& states) {
    for (const State& s : states) offerState(agent, s, true);
  }
  /// The recorder's progress: it holds every step up to `completedStep`.
  void recorderProgress(long completedStep, bool finished) {
    recordedStep_ = std::max(recordedStep_, completedStep);
    while (!unrecorded_.empty() && unrecorded_.front().first <= recordedStep_) unrecorded_.pop_front();
    for (auto& states : unrecordedStates_) {
      while (!states.empty() && message(states.front()).step <= recordedStep_) states.pop_front();
    }
    recorderDone_ = finished;
  }
  /// Ends the run as failed (an agent's failure, a participant gone, the recorder failed).
  void fail(const std::string& reason) { end(Progress::State::Failed, reason); }

  using Ready = RefereeReady;
  /// The node looks again (a state was accepted, a catch-up, its watch, a command, a viewer):
  /// `viewer` says whether one listens on the markers (if one is awaited).
  struct Update {
    bool viewer;
  };
  /// The recorder's progress: it holds every step up to `completedStep`, or it failed (`failure`).
  struct RecorderReport {
    long completedStep;
    bool finished;
    std::string failure;
    bool viewer;
  };
  /// A restarted monitor's first event: what each agent heard and holds (resume()).
  struct Resume {
    std::vector<ProgressAnswer> progress;
    std::vector<std::vector<State>> histories;
  };

  /**
   * The completed steps to publish, then whether the progress changed (start by identity, the
   * flow window, the recorder gate, the end at the last step), and the step to issue a pending
   * command at: the allowed step, but past every step whose status is out (a status counts every
   * command stamped at or before its step, so the recorder knows which commands a step waits for;
   * the allowed step equals the completed one while the agents wait for a lagging recorder).
   */
  Ready step(const Update& e) {
    Ready r;
    r.publish = takeCompleted();
    if (ended()) return r;
    const bool waiting = progress_.state == Progress::State::Waiting;
    r.progress = updateProgress(e.viewer);
    if (ended()) {
      r.progress = false;
      r.finish = true;
      return r;
    }
    const long published = completedStep(), last = monitor_->scenario().steps;
    r.commandsAt = (last <= 0 || published < last) ? std::max(progress_.allowedStep, published + 1) : progress_.allowedStep;
    r.starts = waiting && running();
    return r;
  }
  Ready step(const RecorderReport& e) {
    if (!e.failure.empty()) return step(Failure{"the recorder failed: " + e.failure});
    recorderProgress(e.completedStep, e.finished);
    return step(Update{e.viewer});
  }
  Ready step(const Failure& e) { return endRun(progress_, Progress::State::Failed, e.reason); }
  Ready step(const Blocked&) { return endRun(progress_, Progress::State::Finished, ""); }
  /// Finishes a run that was already over (it fails: it did not witness it); after a resume,
  /// running() is true and the steps it rebuilt come with the next Update.
  Ready step(const Resume& e) {
    const bool wasOver = ended();
    resume(e.progress, e.histories);
    Ready r;
    r.finish = !wasOver && ended();
    return r;
  }

  /// Completed steps in order, each once (step(Update) hands them out with the progress).
  std::vector<FormationSnapshot> takeCompleted() {
    std::vector<FormationSnapshot> done = monitor_->takeCompleted();
    for (const FormationSnapshot& s : done) {
      convergedStep_ = s.converged ? s.convergedStep : -1;
      congruentSinceAt_[s.metrics.step] = convergedStep_;
    }
    return done;
  }
  /// What was published for a completed step, kept until the recorder holds it.
  void keep(long step, Published published) {
    if (recording_) unrecorded_.emplace_back(step, std::move(published));
  }
  /**
   * The progress after the events so far. @param viewer a viewer listens (if one is awaited).
   * @return true if it changed and must be published (progressNow()); a finish or failure is
   * always published (ended()).
   */
  bool updateProgress(bool viewer) {
    if (ended()) return false;
    const long last = monitor_->scenario().steps;
    const long completed = completedStep();
    const long base = recording_ ? std::min(completed, recordedStep_) : completed;
    Progress next = progress_;
    next.completedStep = base;
    if (progress_.state == Progress::State::Waiting) {
      if (base < 0 || !(viewer || !waitForViewer_)) return false;
      next.state = Progress::State::Running;
      started_ = true;
    }
    next.allowedStep = base + window_;
    if (last > 0) next.allowedStep = std::min(next.allowedStep, last);
    if (last > 0 && completed >= last && (!recording_ || recorderDone_)) {
      end(Progress::State::Finished, "");
      return true;
    }
    const long every = std::max<long>(1, window_ / 4);
    const bool agentsMayWait = completed >= progress_.allowedStep;
    if (next.state != progress_.state || next.allowedStep >= progress_.allowedStep + every ||
        (next.allowedStep > progress_.allowedStep && (next.allowedStep == last || agentsMayWait))) {
      acceptUpTo_ = std::max(acceptUpTo_, next.allowedStep);
      const auto at = congruentSinceAt_.find(base);
      next.convergedStep = at == congruentSinceAt_.end() ? -1 : at->second;
      congruentSinceAt_.erase(congruentSinceAt_.begin(), congruentSinceAt_.lower_bound(base));
      progress_ = next;
      return true;
    }
    return false;
  }
  /**
   * A restarted monitor: goes on from the newest progress the agents heard, with the states they
   * still hold. @param progress per agent, @param histories per agent (its unconfirmed states).
   * If the agents' run is already over, it fails saying so (describeOver): it did not witness it.
   * @return false for a new run (nothing done) or a run already over (failed).
   */
  bool resume(const std::vector<ProgressAnswer>& progress, const std::vector<std::vector<State>>& histories) {
    const MonitorResume r = chooseMonitorResume(progress, window_);
    resumedFrom_ = r;
    if (r.over) {
      fail(describeOver(r));
      return false;
    }
    if (!r.resumes()) return false;
    monitor_->startAt(r.step, r.congruentSince);
    progress_.state = Progress::State::Running;
    progress_.completedStep = r.step - 1;
    started_ = true;
    acceptUpTo_ = r.acceptUpTo;
    for (std::size_t i = 0; i < histories.size(); ++i) offerHistory(static_cast<int>(i), histories[i]);
    return true;
  }

  /// Agents whose state at the next step is missing: catch them up from histories.
  std::vector<int> missing() const { return monitor_->missingAt(monitor_->nextStep()); }
  /// Published steps the recorder has not confirmed; worth republishing when it lags.
  const std::deque<std::pair<long, Published>>& unrecorded() const { return unrecorded_; }
  bool recorderLags() const { return recording_ && recordedStep_ < completedStep(); }
  /// Agent i's accepted states the recorder has not confirmed (its `~history` answer).
  const std::deque<State>& unrecordedStates(int agent) const { return unrecordedStates_[static_cast<std::size_t>(agent)]; }
  /// The message a held state is (State itself, or what it points to).
  static decltype(auto) message(const State& s) { return detail::heldMessage(s, 0); }
  /// Agent i's newest state, for its `~recall`; nullptr if none.
  const State* newest(int agent) const {
    return held_[static_cast<std::size_t>(agent)] ? &newest_[static_cast<std::size_t>(agent)] : nullptr;
  }
  /// What the run waits for, in words ("nothing" if for nothing). @param agentName e.g. "agent_3".
  std::string waitingFor(const std::string& recorderName) const {
    const long next = monitor_->nextStep();
    if (recording_ && progress_.state != Progress::State::Waiting && recordedStep_ + window_ < next) {
      return "the recorder " + recorderName + " (it holds steps up to " + std::to_string(recordedStep_) +
             ", and the agents may not run further ahead of it)";
    }
    const std::vector<int> lacking = missing();
    if (!lacking.empty()) return "step " + std::to_string(next) + " of " + agentList(lacking);
    if (recording_ && recordedStep_ < completedStep()) {
      return "the recorder " + recorderName + " (it holds steps up to " + std::to_string(recordedStep_) + ")";
    }
    if (progress_.state == Progress::State::Waiting && waitForViewer_) return "a viewer (rviz) on the markers";
    return "nothing";
  }
  /// "agent_1, agent_4" (the first eight, then how many more).
  static std::string agentList(const std::vector<int>& ids) {
    std::string s;
    for (std::size_t k = 0; k < ids.size(); ++k) {
      if (k == 8) return s + " and " + std::to_string(ids.size() - k) + " more";
      s += (k ? ", " : "") + std::string("agent_") + std::to_string(ids[k]);
    }
    return s;
  }

  /// The choice resume() made (where it went on, the congruent stretch, or why not).
  const MonitorResume& resumedFrom() const { return resumedFrom_; }
  const Progress& progressNow() const { return progress_; }
  bool ended() const { return progress_.state == Progress::State::Finished || progress_.state == Progress::State::Failed; }
  bool running() const { return progress_.state == Progress::State::Running; }
  long completedStep() const { return monitor_->nextStep() - 1; }
  long recordedStep() const { return recordedStep_; }
  long convergedStep() const { return convergedStep_; }
  long acceptUpTo() const { return acceptUpTo_; }
  long window() const { return window_; }
  bool recording() const { return recording_; }
  const FormationMonitor& monitor() const { return *monitor_; }
  /// The commands the agents apply, for the steps measured from now on (FormationMonitor::setSchedule).
  void setSchedule(const CommandSchedule& schedule) { monitor_->setSchedule(schedule); }

 private:
  void end(Progress::State state, const std::string& reason) { endRun(progress_, state, reason); }

  std::unique_ptr<FormationMonitor> monitor_;
  long window_;
  bool recording_, waitForViewer_;
  Progress progress_;
  MonitorResume resumedFrom_;
  bool started_ = false;
  long acceptUpTo_ = 0;
  long recordedStep_ = -1;
  bool recorderDone_ = false;
  long convergedStep_ = -1;
  std::map<long, long> congruentSinceAt_;  // completed step -> first step of its congruent stretch
  std::vector<State> newest_;
  std::vector<bool> held_;
  std::vector<std::deque<State>> unrecordedStates_;  // per agent, at most a window each
  std::deque<std::pair<long, Published>> unrecorded_;
};

}  // namespace vf::protocol
