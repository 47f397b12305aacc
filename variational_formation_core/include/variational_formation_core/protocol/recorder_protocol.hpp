#pragma once

#include <algorithm>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/protocol/progress.hpp"
#include "variational_formation_core/protocol/step_assembler.hpp"
#include "variational_formation_core/agents/record_ledger.hpp"

namespace vf::protocol {

/**
 * The recorder's side of the protocol without a transport (doc/protocol.md, "The recorder"):
 * which states, statuses, markers and commands go into the bag and when, what it reports to the
 * monitor, when it catches up from histories, and when it fails. Each event goes to step(),
 * which returns a Ready: what to do, in order. The recorder node only moves messages and
 * writes the bag.
 *
 * - Each (agent, step) state is kept once (RecordLedger): a repeat is compared bit for bit, and
 *   one that differs fails the recording.
 * - Steps are handed out whole and in order (StepAssembler), and a step only once the recorder
 *   holds every command its status counts; each step says which listed commands to write before it.
 * - Its progress (what it holds whole) is reported every kReportEvery whole steps, and at once
 *   when the agents may be waiting for it (it holds every step the monitor's newest progress it
 *   heard allows) or at its first and last step; a tick reports what is still unreported. Each
 *   report wakes the monitor's threads (doc/benchmarks.md, "Recording at 100 agents, third
 *   round"). The last step finishes the recording.
 * - Catch-up: once its completed step has not moved for a second (caller's clock), it asks for
 *   the histories of the agents whose part of the next step it lacks.
 *
 * State points to the caller's state message (fields step, position, previous_position); Status
 * and Markers are whatever the caller stores (message pointers in the node).
 */
template <class State, class Status, class Markers>
class RecorderProtocol {
 public:
  using Steps = StepAssembler<State, Status, Markers>;
  using Step = typename Steps::Step;
  /// How many commands a status counts (FormationStatus.commands).
  using CommandsCounted = std::function<long(const Status&)>;
  /// The time [s] after which a recorder whose completed step does not move catches up.
  static constexpr double kCatchUpAfter = 1.0;
  /// Whole steps between two reports, at most, unless the agents may be waiting for one.
  static constexpr long kReportEvery = 16;

  /// A whole step to write.
  struct Write {
    Step step;
    std::size_t commands = 0;  ///< > 0: first write the first `commands` listed commands, stamped t_step
  };
  /// What to do after an event, in this order.
  struct Ready {
    bool takeCommands = false;        ///< keep the command list that came (it is the newest)
    std::string dropped;              ///< "" or what was dropped and why
    std::string failed;               ///< "" or why the recording failed (reported, then closed)
    std::vector<Write> write;         ///< whole steps, in step order
    std::optional<Progress> report;   ///< the recorder's progress to publish
    std::string close;                ///< "" or: close the bag, saying how
    int exit = -1;                    ///< >= 0: the recorder is done, with this exit status
    bool catchUp = false;             ///< ask the histories of `fetch` (agents and the monitor), then HistoriesArrived
    std::vector<int> fetch;           ///< the agents whose part of the next step is missing
  };

  struct StateArrived {
    int agent;
    State state;
  };
  struct StatusArrived {
    long step;
    Status status;
  };
  struct MarkersArrived {
    long step;
    Markers markers;
  };
  /// The monitor's list of issued commands: the step each applies from, oldest first.
  struct CommandsArrived {
    std::vector<long> stamps;
  };
  /// The monitor's progress (only its end matters to the recorder).
  struct MonitorProgress {
    Progress progress;
  };
  /// The caller's catch-up timer, at `now` [s].
  struct Tick {
    double now;
  };
  /// The answers to a catch-up (agent, its held states), in the order asked, at `now` [s].
  struct HistoriesArrived {
    double now;
    std::vector<std::pair<int, std::vector<State>>> answers;
  };
  /// The caller cannot go on recording (a file it cannot write).
  struct Failure {
    std::string reason;
  };

  /// @param keptSteps states of each agent kept to compare repeats with; @param lastStep the
  /// scenario's steps (0: unbounded); @param needsMarkers whether step k is whole only with markers.
  RecorderProtocol(int agents, long keptSteps, long lastStep, std::function<bool(long)> needsMarkers,
                   CommandsCounted commandsCounted)
      : ledger_(agents, keptSteps),
        steps_(agents, std::move(needsMarkers)),
        lastStep_(lastStep),
        commandsCounted_(std::move(commandsCounted)) {}

  Ready step(const StateArrived& e) {
    Ready r;
    record(r, e.agent, e.state);
    return r;
  }
  Ready step(const StatusArrived& e) {
    Ready r;
    if (steps_.addStatus(e.step, e.status)) flush(r);  // refused if republished: written once
    return r;
  }
  Ready step(const MarkersArrived& e) {
    Ready r;
    if (steps_.addMarkers(e.step, e.markers)) flush(r);  // refused if republished: written once
    return r;
  }
  Ready step(const CommandsArrived& e) {
    Ready r;
    // The list only grows (a restarted monitor goes on from the kept one): an older copy that
    // arrives late changes nothing.
    if (e.stamps.size() < commands_.size()) return r;
    commands_ = e.stamps;
    commandsInBag_ = std::min(commandsInBag_, commands_.size());
    r.takeCommands = true;
    flush(r);  // steps that waited for these commands
    return r;
  }
  Ready step(const MonitorProgress& e) {
    Ready r;
    monitorAllows_ = std::max(monitorAllows_, e.progress.allowedStep);
    report(r);  // the agents may wait at that step already
    if (over(e.progress)) {
      r.close = e.progress.state == Progress::State::Finished ? "finished" : "the run failed";
      r.exit = 0;
    }
    return r;
  }
  Ready step(const Tick& e) {
    // States published while a connection was coming up (an agent or the recorder restarted)
    // are lost to this subscriber, but their agent (or the monitor) still holds them.
    Ready r;
    if (over(progress_)) return r;
    report(r, true);
    if (progress_.completedStep != lastCatchUpStep_) {
      lastCatchUpStep_ = progress_.completedStep;
      stalledSince_ = e.now;
      return r;
    }
    if (e.now - stalledSince_ < kCatchUpAfter) return r;
    r.catchUp = true;
    for (int i = 0; i < ledger_.agentCount(); ++i) {
      if (ledger_.statesBelow(i) <= progress_.completedStep + 1) r.fetch.push_back(i);
    }
    return r;
  }
  Ready step(const HistoriesArrived& e) {
    Ready r;
    for (const auto& answer : e.answers) {
      for (const State& s : answer.second) {
        if (!ledger_.holdsState(answer.first, s->step)) record(r, answer.first, s);
      }
    }
    stalledSince_ = e.now;
    return r;
  }
  Ready step(const Failure& e) {
    Ready r;
    fail(r, e.reason);
    return r;
  }
  /// Stalls: a start that never came counts from `now` [s].
  void startClock(double now) { stalledSince_ = now; }

  /// The recorder's progress as reported last.
  const Progress& progress() const { return progress_; }
  const Steps& steps() const { return steps_; }
  const RecordLedger& ledger() const { return ledger_; }
  /// Repeated states not written again, and of those the ones too old to compare.
  long repeats() const { return repeats_; }
  long uncompared() const { return uncompared_; }
  /// New states refused by the assembler (of a step already written): 0 unless the rules broke.
  long refused() const { return refused_; }

 private:
  void record(Ready& r, int agent, const State& s) {
    if (!finiteState(s->position, s->previous_position)) {
      // Agents never publish a diverged step (they fail with their last good one): one that
      // comes anyway ends the run as diverged, not a bag with NaNs in it.
      fail(r, "agent_" + std::to_string(agent) + "'s step " + std::to_string(s->step) +
                  " is not finite (the run diverged)");
      return;
    }
    RecordLedger::Arrival arrival = RecordLedger::Arrival::New;
    try {
      arrival = ledger_.addState(agent, s->step, s->position, s->previous_position);
    } catch (const InvalidInput& e) {
      r.dropped = "a state of agent_" + std::to_string(agent) + ": " + e.what();
      return;
    }
    if (arrival == RecordLedger::Arrival::Differs) {
      fail(r, "agent_" + std::to_string(agent) + "'s step " + std::to_string(s->step) +
                  " arrived twice with different positions: a recovery did not reproduce it bit for bit");
      return;
    }
    if (arrival != RecordLedger::Arrival::New) {
      ++repeats_;  // already held (doc/distributed.md, recording)
      uncompared_ += arrival == RecordLedger::Arrival::Unchecked;
      return;
    }
    if (steps_.addState(agent, s->step, s)) {
      flush(r);
    } else {
      ++refused_;  // cannot happen: a written step had all its states
    }
  }
  /// Hands out every whole step (each with the commands that apply from it), then reports.
  void flush(Ready& r) {
    // A step waits for every command its status counts (the monitor stamps none at or before a
    // step whose status is out): the list comes on its own connection, possibly after the status.
    const auto commandsHeld = [this](const Step& step) {
      return static_cast<long>(commands_.size()) >= commandsCounted_(step.status);
    };
    for (Step& step : steps_.takeWhole(commandsHeld)) {
      std::size_t through = commandsInBag_;
      while (through < commands_.size() && commands_[through] <= step.step) ++through;
      Write w{std::move(step), through == commandsInBag_ ? 0 : through};
      commandsInBag_ = through;
      r.write.push_back(std::move(w));
    }
    report(r);
  }
  /// Complete up to k: every agent's state, the status and the markers of steps 0..k are out.
  /// Reported at once if `now`, if the agents may wait for it, at the first and last step, and
  /// every kReportEvery steps; otherwise held back.
  void report(Ready& r, bool now = false) {
    if (over(progress_)) return;
    const long complete = steps_.handedOutThrough();
    if (complete <= progress_.completedStep) return;
    const bool first = progress_.state == Progress::State::Waiting;
    const bool last = lastStep_ > 0 && complete >= lastStep_;
    if (!(now || first || last || complete >= monitorAllows_ || complete >= progress_.completedStep + kReportEvery)) return;
    progress_.completedStep = complete;
    progress_.state = Progress::State::Running;
    if (last) {
      r.close = "complete";
      progress_.state = Progress::State::Finished;
    }
    r.report = progress_;
  }
  /// Ends the recording and tells the monitor, which ends the run as failed, naming the reason.
  void fail(Ready& r, const std::string& reason) {
    progress_.state = Progress::State::Failed;
    progress_.reason = reason;
    r.failed = reason;
    r.report = progress_;
    r.close = "failed";
    r.exit = 1;
  }

  RecordLedger ledger_;  // each state is held once; repeats are compared with it
  Steps steps_;          // steps not yet handed out
  long lastStep_;
  CommandsCounted commandsCounted_;
  Progress progress_;
  std::vector<long> commands_;  // the steps of the newest list's commands
  std::size_t commandsInBag_ = 0;
  long repeats_ = 0, uncompared_ = 0, refused_ = 0;
  long lastCatchUpStep_ = -2;
  long monitorAllows_ = 0;  // the newest allowed step heard from the monitor (it only grows)
  double stalledSince_ = 0.0;
};

}  // namespace vf::protocol
