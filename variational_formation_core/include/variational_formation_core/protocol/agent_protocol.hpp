#pragma once

#include <algorithm>
#include <deque>
#include <exception>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "variational_formation_core/agents/lockstep_agent.hpp"
#include "variational_formation_core/protocol/command_desk.hpp"
#include "variational_formation_core/protocol/progress.hpp"

namespace vf::protocol {

/**
 * One lockstep agent's side of the protocol without a transport (doc/protocol.md, "The agent"):
 * the gates, the histories and the failures around a LockstepAgent, which does all the maths.
 * Each event (a state on a topic, the monitor's progress, its command list, a wake-up) goes to
 * step(), which returns a Ready: what to do, in order. The agent node (and the tests' simulated
 * network) only moves messages between its transport and this class.
 *
 * - Flow gate: it computes step k + 1 only while k < the newest allowed step it heard, once it
 *   holds every command the newest progress counts, and never after the run is over or it failed.
 * - Pacing: with a real-time factor r > 0, step k + 1 is due (k + 1 - k0) h / r [s] after the
 *   first step it computed (from k0), on the caller's clock (read for pacing only).
 * - Histories: its published states, and the neighbours' states it accepted, after the newest
 *   completed step it heard (served to a restarted monitor or recorder, `~history`).
 * - Failures: a step that is not finite is undone and its last good state published with the
 *   reason; so is a listed command it cannot apply. Either ends its stepping; the monitor ends
 *   the run.
 * - Resumed behind: a neighbour's state two or more steps past a restarted agent's step, before
 *   its first update, means that neighbour used a newer state of it (the dead incarnation's last,
 *   which reached it after the holders were asked). It asks the holders again (Ready::recallAgain),
 *   resumes from their answer (Recalled), and then takes the states it kept.
 * - Lost everywhere: when the holders have nothing newer, our next state may exist nowhere (an
 *   agent_manager killed with it in its unsent batch, while a neighbour's state computed from it
 *   had left on its own topic). Then it asks the holders of each neighbour that is ahead for that
 *   neighbour's states after our step (Ready::askNeighbourHistories), and computes the lost
 *   steps again from them (NeighbourHistories): the same operands, so the same states.
 *
 * StatePtr points to the caller's state message (fields id, step, position, previous_position);
 * it is built by `make` and kept as it is, so histories serve exactly what was published.
 * ProgressMsg is the caller's progress message, kept as it came for `~history`.
 */
template <class StatePtr, class ProgressMsg>
class AgentProtocol {
 public:
  /// Builds the state message of the agent's current step (`failure`: "" or why it ends the run).
  using MakeState = std::function<StatePtr(const LockstepAgent& agent, const std::string& failure)>;
  /// The caller's clock [s] (only differences are used; needed with a real-time factor).
  using Clock = std::function<double()>;

  /// What to do after an event, in this order.
  struct Ready {
    std::vector<StatePtr> publish;  ///< states to publish, oldest first (already in the history)
    std::string failed;             ///< "" or why this agent ends the run (the last state says it too)
    std::string dropped;            ///< "" or what was dropped and why (counted in the agent's `dropped`)
    std::string note;               ///< "" or a line to log: an answer that did not move the agent on (not counted)
    std::string over;               ///< "" or: the run just ended (a line to log)
    bool wakeWhenSensed = false;    ///< waits for states: wake (Wake) when the shared board holds the step
    double wakeAfter = -1.0;        ///< >= 0: the pacing timer; wake (Wake) after this many seconds
    /// Ask the holders again where to resume (as at a restart) and give their answer to step(Recalled).
    bool recallAgain = false;
    long resumedAt = -1;            ///< >= 0: it resumed at this step on a Recalled answer
    /// Neighbours past our step + 1 whose older states we need: ask each one's holders (itself and
    /// its neighbours, `~history` with its id) and give the states to step(NeighbourHistories).
    std::vector<int> askNeighbourHistories;

    /// Back to "nothing to do", keeping the buffers (every field above, as initialised).
    void clear() {
      publish.clear();
      failed.clear();
      dropped.clear();
      note.clear();
      over.clear();
      wakeWhenSensed = false;
      wakeAfter = -1.0;
      recallAgain = false;
      resumedAt = -1;
      askNeighbourHistories.clear();
    }
  };

  /// A state on agent `topic`'s topic (already checked to come from its owner).
  struct StateArrived {
    int topic;
    StatePtr state;
  };
  /// The monitor's progress: what the agent reads of it, and the message itself.
  struct ProgressArrived {
    AgentProgress progress;
    ProgressMsg message;
  };
  /// The monitor's list of issued commands: `listed` entries, entry(k) the k-th (0-based).
  struct CommandsArrived {
    long listed;
    std::function<IssuedCommand(long)> entry;
  };
  /// The pacing timer or the shared board says the agent may go on.
  struct Wake {};
  /// The answer to Ready::askNeighbourHistories: the states of those neighbours their holders
  /// hold, in any order, repeats allowed; the caller checked that each is the state of the
  /// neighbour whose history it asked for (`topic` = that neighbour's id).
  struct NeighbourHistories {
    std::vector<StateArrived> states;
  };
  /// The holders' answer after Ready::recallAgain: the newest state of this agent they hold.
  struct Recalled {
    long step = -1;  ///< -1: none beyond step 0
    std::vector<double> position, previousPosition;
  };

  /// @param realTimeFactor r (>= 0; 0: as fast as possible), validated by the caller.
  /// @param earliness how early a paced step may start [s] (>= 0): one due sooner goes now, so
  ///        that a pacer releasing a process's agents together never waits for another's due.
  AgentProtocol(LockstepAgent agent, MakeState make, double realTimeFactor = 0.0, Clock clock = Clock(),
                double earliness = 0.0)
      : agent_(std::move(agent)),
        make_(std::move(make)),
        clock_(std::move(clock)),
        realTimeFactor_(realTimeFactor),
        earliness_(earliness),
        neighbourHistory_(agent_.neighbourIds().size()) {}

  /// Crash recovery, before start(): resumes the agent at `step` (LockstepAgent::resume).
  /// @throws InvalidInput if the state does not fit; the agent is then unchanged.
  void resume(long step, const std::vector<double>& position, const std::vector<double>& previousPosition) {
    agent_.resume(step, position, previousPosition);
  }
  /// The first state (step 0 or the recovered one).
  Ready start() {
    Ready r;
    publishNow(r);
    return r;
  }

  Ready step(const StateArrived& e) {
    Ready r;
    offer(r, e);
    return r;
  }
  /// As step(e), into `r` (cleared first): a caller that keeps one Ready for the states it reads
  /// allocates nothing per state.
  void step(const StateArrived& e, Ready& r) {
    r.clear();
    offer(r, e);
  }

  Ready step(const Recalled& e) {
    Ready r;
    recalling_ = false;
    if (e.step <= agent_.step() || agent_.advancedSinceResume()) {
      // Nothing was dropped: the holders simply hold nothing newer yet (their answer can come
      // before the dead incarnation's last states reach them). The next newer state asks again.
      r.note = "the holders' newest state of this agent (step " + std::to_string(e.step) +
               ") is not past step " + std::to_string(agent_.step()) + "; waiting for a newer one";
      if (!ahead_.empty() && !agent_.advancedSinceResume() && historiesAskedAt_ < askedAt_) {
        // Our next state may exist nowhere: compute it again from the neighbours' older states.
        historiesAskedAt_ = askedAt_;
        historiesOf_.clear();  // a newer state ahead: their holders may hold more by now
        for (const StateArrived& k : ahead_) askHistoryOf(r, k.topic);
        r.note = "no holder has a state of this agent past step " + std::to_string(agent_.step()) + ", though " +
                 aheadList() + " computed from one: asking their holders for their states from step " +
                 std::to_string(agent_.step()) + " on, to compute the lost steps again";
      }
      return r;
    }
    try {
      agent_.resume(e.step, e.position, e.previousPosition);
    } catch (const std::exception& ex) {
      r.dropped = std::string("a recalled state: ") + ex.what();
      return r;
    }
    r.resumedAt = e.step;
    publishNow(r);  // the recovered state, as start() publishes it
    std::vector<StateArrived> kept;
    kept.swap(ahead_);
    for (const StateArrived& s : kept) offer(r, s);
    advance(r);
    return r;
  }

  /// Takes the states of the neighbours that are ahead from their holders' histories, and uses
  /// each once the agent reaches its step (the lost steps are computed again, exactly).
  Ready step(const NeighbourHistories& e) {
    Ready r;
    fetchingHistories_ = false;
    std::size_t kept = 0;
    for (const StateArrived& s : e.states) {
      if (s.state && s.state->step >= agent_.step()) {
        backfill_.push_back(s);
        ++kept;
      }
    }
    std::stable_sort(backfill_.begin(), backfill_.end(),
                     [](const StateArrived& a, const StateArrived& b) { return a.state->step < b.state->step; });
    r.note = kept == 0 ? "the holders of " + aheadList() + " hold none of their states from step " +
                             std::to_string(agent_.step()) + " on; waiting"
                       : std::to_string(kept) + " state(s) of " + aheadList() +
                             " from their holders, each used when this agent reaches its step";
    advance(r);
    return r;
  }

  Ready step(const ProgressArrived& e) {
    Ready r;
    // Once its run is over, an agent keeps that run's final word: a monitor started later (which
    // says that the run is over) does not change it.
    if (exitStatus_ >= 0) return r;
    const Progress& p = e.progress.progress;
    if (!hasProgress_ || p.completedStep >= heardCompleted_) {
      lastProgress_ = e.message;
      heardCompleted_ = p.completedStep;
      hasProgress_ = true;
      trimHistories(p.completedStep);
    }
    if (over(p)) {
      // Stay up, idle: a respawning agent that exited would only be restarted.
      const bool finished = p.state == Progress::State::Finished;
      r.over = "the run is over at step " + std::to_string(agent_.step()) + " (" +
               (finished ? std::string("finished") : "failed: " + p.reason) + "); idle until shut down";
      exitStatus_ = finished ? 0 : 1;
    } else {
      allowedStep_ = std::max(allowedStep_, p.allowedStep);
      commandsCounted_ = e.progress.commands;
      advance(r);
    }
    return r;
  }

  Ready step(const CommandsArrived& e) {
    Ready r;
    while (failure_.empty() && commandsHeld_ < e.listed) {
      const IssuedCommand c = e.entry(commandsHeld_);
      std::string error;
      const LockstepAgent::CommandReceipt receipt = agent_.receiveCommand(c.first, c.second, &error);
      if (receipt != LockstepAgent::CommandReceipt::Accepted) {
        // The monitor checked it and stamped it at a step no agent had passed: this cannot be
        // made exact any more, so the run ends, saying why.
        fail(r, "command " + std::to_string(commandsHeld_ + 1) + " (from step " + std::to_string(c.first) +
                    ") refused at step " + std::to_string(agent_.step()) + ": " +
                    (receipt == LockstepAgent::CommandReceipt::Late ? std::string("it came after that step") : error));
        return r;
      }
      ++commandsHeld_;
    }
    advance(r);
    return r;
  }

  Ready step(const Wake&) {
    Ready r;
    advance(r);
    return r;
  }

  /// What it waits for, in words. @param monitor the monitor's node name.
  std::string waitingFor(const std::string& monitor) const {
    if (!failure_.empty()) return "the monitor to end the run (" + failure_ + ")";
    if (!ahead_.empty() && !agent_.advancedSinceResume()) {
      const StateArrived& newest = *std::max_element(ahead_.begin(), ahead_.end(), [](const StateArrived& a, const StateArrived& b) {
        return a.state->step < b.state->step;
      });
      return "a newer state of its own: agent_" + std::to_string(newest.topic) + " is at step " +
             std::to_string(newest.state->step) + ", past step " + std::to_string(agent_.step()) + " + 1" +
             (recalling_ ? " (asking the holders again)"
                         : fetchingHistories_ ? " (none held one; asking " + aheadList() + "'s holders for their older states)"
                                              : " (the holders asked had none newer)");
    }
    if (agent_.finished()) return "the monitor to end the run (last step " + std::to_string(agent_.step()) + " done)";
    if (agent_.step() >= allowedStep_) {
      return allowedStep_ == 0 ? "the monitor " + monitor + " to start the run (it waits for every participant)"
                               : "the monitor " + monitor + " to allow step " + std::to_string(agent_.step() + 1) +
                                     " (flow control: it or the recorder is behind)";
    }
    if (commandsHeld_ < commandsCounted_) {
      return "command " + std::to_string(commandsHeld_ + 1) + " of " + std::to_string(commandsCounted_) +
             " on the monitor's latched `command`";
    }
    std::string missing;
    const auto add = [&missing](int j) { missing += (missing.empty() ? "" : ", ") + std::string("agent_") + std::to_string(j); };
    for (int j : agent_.neighbourIds()) {
      if (!agent_.holdsNeighbourStep(j)) add(j);
    }
    if (missing.empty()) {  // with safety: every agent's state at the step (doc/distributed.md, "Sensing")
      for (int j : agent_.missingSensed(5)) add(j);
      if (!missing.empty()) missing += " (sensing)";
    }
    return missing.empty() ? "its pacing timer" : "the state at step " + std::to_string(agent_.step()) + " of " + missing;
  }

  const LockstepAgent& agent() const { return agent_; }
  /// The held states of agent `id` after the newest completed step heard: its own published ones
  /// (id = this agent) or a neighbour's accepted ones; nullptr for another agent.
  const std::deque<StatePtr>* history(int id) const {
    if (id == agent_.id()) return &history_;
    const std::vector<int>& ids = agent_.neighbourIds();
    const auto k = static_cast<std::size_t>(std::find(ids.begin(), ids.end(), id) - ids.begin());
    return k < ids.size() ? &neighbourHistory_[k] : nullptr;
  }
  bool hasProgress() const { return hasProgress_; }
  /// The newest progress heard (by completed step); a default message before any.
  const ProgressMsg& lastProgress() const { return lastProgress_; }
  /// -1 while the run goes on; 0 once the monitor said it finished, 1 failed.
  int exitStatus() const { return exitStatus_; }
  const std::string& failure() const { return failure_; }
  long allowedStep() const { return allowedStep_; }
  long commandsHeld() const { return commandsHeld_; }

 private:
  void offer(Ready& r, const StateArrived& e) {
    try {
      const auto& msg = *e.state;
      const long sender = static_cast<long>(msg.id) == e.topic ? e.topic : -1;
      const auto receipt = agent_.receive(sender, msg.step, msg.position, msg.previous_position);
      if (receipt == LockstepAgent::Receipt::Accepted) {
        accepted(r, e);
      } else if (receipt == LockstepAgent::Receipt::ImpossibleStep && sender >= 0 && msg.step > agent_.step() + 1 &&
                 !agent_.advancedSinceResume()) {
        keepAhead(r, e);
      } else if (receipt != LockstepAgent::Receipt::Duplicate) {
        r.dropped = "a state from agent_" + std::to_string(e.topic) + " (step " + std::to_string(msg.step) +
                    "): " + LockstepAgent::describe(receipt);
      }
    } catch (const std::exception& ex) {
      r.dropped = std::string("a state: ") + ex.what();
    }
  }
  /// A state two or more steps past ours before our first update: its sender computed from a
  /// newer state of ours than the one we resumed from. Kept (the newest per sender) until the
  /// holders answer again; asked once per newer such step, so an answer that is no newer waits
  /// for the next one instead of asking in a loop.
  void keepAhead(Ready& r, const StateArrived& e) {
    const auto same = std::find_if(ahead_.begin(), ahead_.end(), [&e](const StateArrived& k) { return k.topic == e.topic; });
    if (same == ahead_.end()) {
      ahead_.push_back(e);
    } else if (same->state->step < e.state->step) {
      *same = e;
    }
    if (!recalling_ && e.state->step > askedAt_) {
      recalling_ = true;
      askedAt_ = e.state->step;
      r.recallAgain = true;
    } else if (historiesAskedAt_ >= 0) {
      askHistoryOf(r, e.topic);  // another neighbour ahead, after the holders had nothing newer
    }
  }
  /// Asks (once per neighbour) for neighbour j's states held in its holders' histories.
  void askHistoryOf(Ready& r, int j) {
    if (std::find(historiesOf_.begin(), historiesOf_.end(), j) != historiesOf_.end()) return;
    historiesOf_.push_back(j);
    fetchingHistories_ = true;
    r.askNeighbourHistories.push_back(j);
  }
  /// Computes every step the gates allow, then offers the states kept for later that became usable.
  void advance(Ready& r) {
    advanceSteps(r);
    if (!backfill_.empty() || !ahead_.empty()) releaseKept(r);
  }
  /// After a resume only: offers the kept states whose step has come, in step order.
  __attribute__((noinline, cold)) void releaseKept(Ready& r) {
    if (releasing_) return;
    // Offers below advance the agent again (offer -> advance): this loop alone releases.
    releasing_ = true;
    for (bool offered = true; offered;) {
      offered = false;
      const long usable = agent_.step() + 1;
      if (!backfill_.empty() && backfill_.front().state->step <= usable) {
        const StateArrived s = backfill_.front();
        backfill_.erase(backfill_.begin());
        offerQuietly(r, s);
        offered = true;
        continue;
      }
      if (!agent_.advancedSinceResume()) continue;
      // Kept while resumed behind; once it moved on, each is taken when its step comes.
      for (auto it = ahead_.begin(); it != ahead_.end(); ++it) {
        if (it->state->step <= usable) {
          const StateArrived s = *it;
          ahead_.erase(it);
          offer(r, s);
          offered = true;
          break;
        }
      }
    }
    releasing_ = false;
  }
  /// A state from a holder's history: one that is of no use (older than the one held, or a
  /// repeat) is no fault of its sender's, so nothing is reported.
  void offerQuietly(Ready& r, const StateArrived& e) {
    const auto& msg = *e.state;
    if (static_cast<long>(msg.id) != e.topic) return;
    try {
      if (agent_.receive(e.topic, msg.step, msg.position, msg.previous_position) == LockstepAgent::Receipt::Accepted) {
        accepted(r, e);
      }
    } catch (const std::exception& ex) {
      r.dropped = std::string("a state from a holder's history: ") + ex.what();
    }
  }
  /// A state the agent accepted: into its sender's history (a neighbour's), then on.
  void accepted(Ready& r, const StateArrived& e) {
    const std::vector<int>& ids = agent_.neighbourIds();
    const auto k = static_cast<std::size_t>(std::find(ids.begin(), ids.end(), e.topic) - ids.begin());
    if (k < ids.size()) neighbourHistory_[k].push_back(e.state);
    advance(r);
  }
  /// "agent_3, agent_5": the senders of the states kept past our step + 1.
  std::string aheadList() const {
    std::string s;
    for (const StateArrived& k : ahead_) s += (s.empty() ? "" : ", ") + std::string("agent_") + std::to_string(k.topic);
    return s.empty() ? "the neighbours" : s;
  }
  /// Computes every step the gates allow (the flow gate is this loop's condition).
  void advanceSteps(Ready& r) {
    while (exitStatus_ < 0 && failure_.empty() && !agent_.finished() && agent_.step() < allowedStep_ &&
           commandsHeld_ >= commandsCounted_) {
      if (!agent_.ready()) {
        r.wakeWhenSensed = true;
        return;
      }
      // The clock is read for pacing only: unpaced, a step needs no time of day.
      const double now = realTimeFactor_ > 0.0 && clock_ ? clock_() : 0.0;
      if (!started_) {
        started_ = true;
        startedAt_ = now;
        startStep_ = agent_.step();
      }
      if (realTimeFactor_ > 0.0) {
        // Step k + 1 is due (k + 1 - k0) h / r after the start at step k0.
        const double due = static_cast<double>(agent_.step() + 1 - startStep_) * agent_.scenario().timeStep / realTimeFactor_;
        const double wait = due - (now - startedAt_);
        if (wait > earliness_) {
          r.wakeAfter = wait;
          return;
        }
      }
      agent_.advance();
      if (!agent_.finite()) {
        // Never publish a non-finite state: report the divergence with the last good one, and
        // let the monitor end the run (doc/distributed.md).
        const std::string why = "step " + std::to_string(agent_.step()) + " is not finite (the run diverged)";
        agent_.undo();
        fail(r, why);
        return;
      }
      publishNow(r);
    }
  }
  void fail(Ready& r, const std::string& why) {
    failure_ = why;
    r.failed = why;
    publishNow(r);
  }
  void publishNow(Ready& r) {
    StatePtr s = make_(agent_, failure_);
    history_.push_back(s);
    r.publish.push_back(std::move(s));
  }
  void trimHistories(long completed) {
    while (!history_.empty() && history_.front()->step <= completed) history_.pop_front();
    for (auto& held : neighbourHistory_) {
      while (!held.empty() && held.front()->step <= completed) held.pop_front();
    }
  }

  LockstepAgent agent_;
  MakeState make_;
  Clock clock_;
  double realTimeFactor_;
  double earliness_;  // [s]
  std::deque<StatePtr> history_;  // published states after the newest completed step heard
  // Neighbours' states accepted after that step, indexed like neighbourIds(): a state of an
  // incarnation that died may exist nowhere else (doc/distributed.md, recovery).
  std::vector<std::deque<StatePtr>> neighbourHistory_;
  ProgressMsg lastProgress_{};
  bool hasProgress_ = false;
  long heardCompleted_ = -1;
  long allowedStep_ = 0;
  long commandsHeld_ = 0;     // commands of the monitor's list applied
  long commandsCounted_ = 0;  // commands the newest progress counts: the agent steps only once it holds them
  bool started_ = false;
  double startedAt_ = 0.0;
  long startStep_ = 0;
  int exitStatus_ = -1;
  std::string failure_;
  std::vector<StateArrived> ahead_;  // states past our step + 1, kept while the holders are asked again
  bool recalling_ = false;           // Ready::recallAgain said, no Recalled yet
  long askedAt_ = -1;                // the newest kept step that made it ask
  long historiesAskedAt_ = -1;       // askedAt_ when it last asked for the neighbours' histories
  std::vector<int> historiesOf_;     // the neighbours whose histories it asked for
  bool fetchingHistories_ = false;   // Ready::askNeighbourHistories said, no NeighbourHistories yet
  std::vector<StateArrived> backfill_;  // neighbours' states from their holders, by step, until usable
  bool releasing_ = false;           // advance() is offering kept states
};

}  // namespace vf::protocol
