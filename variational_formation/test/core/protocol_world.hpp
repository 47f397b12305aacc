#pragma once
// A whole lockstep run without a transport, for the protocol tests: the shipped agents
// (AgentProtocol, as AgentNode runs it), the monitor's LockstepReferee and the shipped recorder
// (RecorderProtocol, as RecorderNode runs it), joined by a simulated network whose deliveries, repeats,
// reorderings, losses, kills and restarts a test chooses event by event.

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "variational_formation_core/agents/lockstep_agent.hpp"
#include "variational_formation_core/protocol/agent_protocol.hpp"
#include "variational_formation_core/protocol/recovery.hpp"
#include "variational_formation_core/protocol/lockstep_referee.hpp"
#include "variational_formation_core/protocol/recorder_protocol.hpp"
#include "variational_formation_core/integrators/variational_integrator.hpp"

namespace vf::test {

/// An AgentState without ROS: the fields the protocol reads.
struct State {
  int id = -1;
  long step = -1;
  std::vector<double> position, previous_position;
};
using StatePtr = std::shared_ptr<const State>;
using Referee = protocol::LockstepReferee<State, long>;
using Progress = protocol::Progress;
using AgentProtocol = protocol::AgentProtocol<StatePtr, Progress>;
using Recorder = protocol::RecorderProtocol<StatePtr, long, long>;  // a status and markers are their step

/// One message on its way. Kinds: a state (to a neighbour, the monitor or the recorder), a
/// progress (to an agent or the recorder), a status or markers (to the recorder), a recorder
/// progress (to the monitor).
struct Message {
  enum class Kind { State, Progress, Status, Markers, RecorderProgress } kind;
  enum To { Monitor = -1, Recorder = -2 };
  int to = 0;  ///< an agent id, Monitor or Recorder
  State state;
  Progress progress;
  long step = -1;  ///< of a status or markers
  bool finished = false;  ///< of a recorder progress
  int from = -1;  ///< the publishing agent of a state
};

class World {
 public:
  World(const Scenario& s, long window, long markerEvery)
      : scenario_(s),
        formation_(makeFormation(s)),
        window_(window),
        markerEvery_(markerEvery),
        recorder_(s.agentCount(), 1024, s.steps, [this](long k) { return needsMarkers(k); }, [](long) { return 0L; }) {
    VariationalIntegrator reference(formation_, s.initialPositions, s.initialVelocities, s.timeStep, s.dampingGain,
                                    StartMethod::Variational);
    expected_.push_back(reference.positions());
    for (long k = 0; k < s.steps; ++k) {
      reference.step();
      expected_.push_back(reference.positions());
    }
    agents_.resize(static_cast<std::size_t>(s.agentCount()));
    for (int i = 0; i < s.agentCount(); ++i) startAgent(i);
    startMonitor();
  }

  // ---- events ----
  /// Delivers the oldest in-flight message on message m's connection (TCP keeps each
  /// connection's order; connections overtake each other), removing it unless `repeat`.
  void deliver(std::size_t m, bool repeat = false) {
    m = head(m);
    const Message msg = inFlight_[m];
    if (!repeat) inFlight_.erase(inFlight_.begin() + static_cast<long>(m));
    ++delivered_;
    switch (msg.kind) {
      case Message::Kind::State:
        if (msg.to == Message::Monitor) {
          if (monitor_) monitorGotState(msg.state.id, msg.state);
        } else if (msg.to == Message::Recorder) {
          record(msg.state.id, msg.state);
        } else {
          agentGotState(msg.to, msg.state);
        }
        break;
      case Message::Kind::Progress:
        if (msg.to == Message::Recorder) {
          recorderGotProgress(msg.progress);
        } else {
          agentGotProgress(msg.to, msg.progress);
        }
        break;
      case Message::Kind::Status:
        recorderDo(recorder_.step(Recorder::StatusArrived{msg.step, msg.step}));
        break;
      case Message::Kind::Markers:
        recorderDo(recorder_.step(Recorder::MarkersArrived{msg.step, msg.step}));
        break;
      case Message::Kind::RecorderProgress:
        if (monitor_) monitorDo(monitor_->step(Referee::RecorderReport{msg.step, msg.finished, "", true}));
        break;
    }
  }
  /// Loses message m (a publisher that died with it in its queue, or one overtaken on a new connection).
  void lose(std::size_t m) { inFlight_.erase(inFlight_.begin() + static_cast<long>(m)); }
  /// Loses message m as a connection that comes up again loses it: the subscriber then gets the
  /// topic's latched newest message instead (states, status and markers are latched).
  void reconnect(std::size_t m) {
    Message msg = inFlight_[m];
    for (std::size_t k = inFlight_.size(); k-- > 0;) {
      if (sameConnection(inFlight_[k], msg)) lose(k);
    }
    if (msg.kind == Message::Kind::State) {
      msg.state = latched_[msg.from];
    } else if (msg.kind == Message::Kind::Status || msg.kind == Message::Kind::Markers) {
      if (latchedStatus_ < 0) return;
      msg.step = latchedStatus_;
      if (msg.kind == Message::Kind::Markers && !needsMarkers(msg.step)) return;
    }
    send(msg);
  }
  /// Kills agent i; the messages it had not sent yet are lost with it (each with probability lossChance).
  void killAgent(int i, std::mt19937& rng, double lossChance) {
    trace("kill agent " + std::to_string(i));
    agents_[static_cast<std::size_t>(i)].reset();
    latched_.erase(i);  // its latched topic went with it: a new subscriber gets nothing until it publishes again
    // Each connection from it loses a random tail of its queue (with probability lossChance).
    std::bernoulli_distribution lost(lossChance);
    std::map<int, bool> tailLost;  // by receiver
    for (std::size_t k = inFlight_.size(); k-- > 0;) {
      const int to = inFlight_[k].to;  // a copy: lose(k) erases the message
      if (to == i) {
        lose(k);
      } else if (inFlight_[k].kind == Message::Kind::State && inFlight_[k].from == i) {
        if (!tailLost.count(to)) tailLost[to] = lost(rng);
        if (tailLost[to]) lose(k);
        tailLost[to] = tailLost[to] && lost(rng);
      }
    }
  }
  /// Restarts agent i (asks its neighbours and the monitor where to resume). With
  /// `deliverFirst`, what the dead incarnation did send arrives before the new one asks its
  /// holders (a respawn usually takes far longer than a delivery); without, it stays in flight
  /// (a loaded machine; ProtocolRun.LateStateOfTheDeadIncarnationMakesTheNewOneRecallAgain).
  void restartAgent(int i, bool deliverFirst = true) {
    trace("restart agent " + std::to_string(i));
    for (std::size_t k = 0; deliverFirst && k < inFlight_.size();) {
      if (inFlight_[k].kind == Message::Kind::State && inFlight_[k].from == i) {
        deliver(k);
        k = 0;
      } else {
        ++k;
      }
    }
    startAgent(i);
  }
  void killMonitor() {
    trace("kill monitor");
    monitor_.reset();
    inFlight_.erase(std::remove_if(inFlight_.begin(), inFlight_.end(),
                                   [](const Message& m) {
                                     return m.to == Message::Monitor || m.kind == Message::Kind::Status ||
                                            m.kind == Message::Kind::Markers || m.kind == Message::Kind::Progress;
                                   }),
                    inFlight_.end());
  }
  void restartMonitor() {
    trace("restart monitor");
    startMonitor();
  }
  /// The monitor's and the recorder's stall timers: catch up from histories, republish.
  void stallTimers() {
    if (monitor_ && !monitor_->ended()) monitorCatchUp();
    recorderCatchUp();
  }

  // ---- what a test looks at ----
  std::vector<Message>& inFlight() { return inFlight_; }
  bool agentAlive(int i) const { return agents_[static_cast<std::size_t>(i)] != nullptr; }
  bool monitorAlive() const { return monitor_ != nullptr; }
  const Referee* referee() const { return monitor_.get(); }
  int agentCount() const { return scenario_.agentCount(); }
  bool finished() const { return finished_; }
  bool failed() const { return !failure_.empty(); }
  const std::string& failure() const { return failure_; }
  long writtenThrough() const { return recorder_.steps().handedOutThrough(); }
  long delivered() const { return delivered_; }
  long maxPendingSteps() const { return maxPending_; }
  /// How many progress reports the recorder sent.
  long recorderReports() const { return recorderReports_; }
  /// How often a restarted agent asked its holders again (Ready::recallAgain).
  long recalledAgain() const { return recalledAgain_; }
  /// How often a restarted agent asked for its neighbours' histories (Ready::askNeighbourHistories).
  long historiesAsked() const { return historiesAsked_; }
  /// The newest step any live agent computed.
  long newestAgentStep() const {
    long newest = -1;
    for (const auto& a : agents_) {
      if (a) newest = std::max(newest, a->agent().step());
    }
    return newest;
  }
  const std::vector<std::string>& violations() const { return violations_; }
  /// What each live participant waits for (the monitor's line, the recorder's oldest step).
  std::string waitingFor() const {
    std::string s = monitor_ ? "monitor: " + monitor_->waitingFor("recorder") : "monitor: dead";
    s += "; recorder: " + recorder_.steps().lacking();
    if (std::getenv("PROTOCOL_TRACE")) {
      for (std::size_t i = 0; i < agents_.size(); ++i) {
        const AgentProtocol* a = agents_[i].get();
        s += "\n  agent " + std::to_string(i) + (a ? ": step " + std::to_string(a->agent().step()) + " allowed " +
                                                         std::to_string(a->allowedStep()) + (a->agent().ready() ? " ready" : "") +
                                                         (a->exitStatus() >= 0 ? " over" : "") + " history " +
                                                         std::to_string(a->history(a->agent().id())->size())
                                                   : ": dead");
      }
      if (monitor_) {
        const auto& p = monitor_->progressNow();
        s += "\n  progress completed " + std::to_string(p.completedStep) + " allowed " + std::to_string(p.allowedStep) +
             " monitor completed " + std::to_string(monitor_->completedStep()) + " recorded " + std::to_string(monitor_->recordedStep());
      }
    }
    return s;
  }

 private:
  /// An agent's held states of agent j (its own or a neighbour's), oldest first.
  static std::vector<State> held(const AgentProtocol& a, int j) {
    std::vector<State> states;
    if (const auto* h = a.history(j)) {
      for (const StatePtr& s : *h) states.push_back(*s);
    }
    return states;
  }

  static bool sameConnection(const Message& a, const Message& b) {
    return a.kind == b.kind && a.to == b.to && a.from == b.from;
  }
  std::size_t head(std::size_t m) const {
    for (std::size_t k = 0; k < m; ++k) {
      if (sameConnection(inFlight_[k], inFlight_[m])) return k;
    }
    return m;
  }
  bool needsMarkers(long k) const { return k % markerEvery_ == 0 || (scenario_.steps > 0 && k == scenario_.steps); }

  void send(Message m) { inFlight_.push_back(std::move(m)); }
  /// Carries out what agent i's protocol said: its states go to its neighbours, the monitor and
  /// the recorder, in order. No agent of these runs fails.
  void carryOut(int i, const AgentProtocol::Ready& ready) {
    if (!ready.failed.empty()) violations_.push_back("agent " + std::to_string(i) + " failed: " + ready.failed);
    const AgentProtocol& a = *agents_[static_cast<std::size_t>(i)];
    for (const StatePtr& s : ready.publish) {
      latched_[i] = *s;
      Message m{Message::Kind::State, 0, *s, {}, -1, false, i};
      for (int j : a.agent().neighbourIds()) {
        m.to = j;
        send(m);
      }
      m.to = Message::Monitor;
      send(m);
      m.to = Message::Recorder;
      send(m);
    }
    if (ready.recallAgain) {  // the node asks from a thread of its own; here the holders answer at once
      ++recalledAgain_;
      trace("agent " + std::to_string(i) + " recalls again");
      AgentProtocol::Recalled answer;
      if (const std::optional<State> found = recall(i)) answer = {found->step, found->position, found->previous_position};
      carryOut(i, agents_[static_cast<std::size_t>(i)]->step(answer));
    }
    if (!ready.askNeighbourHistories.empty()) {  // as AgentNode asks: each one's own and its neighbours' `~history`
      ++historiesAsked_;
      trace("agent " + std::to_string(i) + " asks for its neighbours' histories");
      AgentProtocol::NeighbourHistories answer;
      for (int j : ready.askNeighbourHistories) {
        std::vector<int> holders{j};
        for (const Neighbour& k : formation_.neighbours(j)) {
          if (k.agent != i) holders.push_back(k.agent);
        }
        for (int h : holders) {
          if (const AgentProtocol* a = agents_[static_cast<std::size_t>(h)].get()) {
            for (const State& st : held(*a, j)) answer.states.push_back({j, std::make_shared<const State>(st)});
          }
        }
      }
      carryOut(i, agents_[static_cast<std::size_t>(i)]->step(answer));
    }
  }
  /// What restarting agent i's holders (its neighbours, then the monitor) answer to `~recall`:
  /// the newest state of it they hold, chosen as the node chooses (protocol::chooseAgentResume).
  std::optional<State> recall(int i) const {
    std::vector<protocol::RecallAnswer> answers;
    std::vector<State> found;
    for (int j : agents_[static_cast<std::size_t>(i)]->agent().neighbourIds()) {
      protocol::RecallAnswer r;
      State s;
      r.answered = agents_[static_cast<std::size_t>(j)] != nullptr;
      if (r.answered) {
        r.held = agents_[static_cast<std::size_t>(j)]->agent().neighbourState(i, s.step, s.position, s.previous_position);
        r.step = s.step;
      }
      answers.push_back(r);
      found.push_back(s);
    }
    protocol::RecallAnswer r;
    State s;
    r.answered = monitor_ != nullptr;
    if (r.answered && monitor_->newest(i)) {
      s = *monitor_->newest(i);
      r.held = true;
      r.step = s.step;
    }
    answers.push_back(r);
    found.push_back(s);
    const int k = protocol::chooseAgentResume(answers);
    if (k < 0) return std::nullopt;
    return found[static_cast<std::size_t>(k)];
  }
  void startAgent(int i) {
    auto a = std::make_unique<AgentProtocol>(LockstepAgent(scenario_, i), [](const LockstepAgent& c, const std::string&) {
      return std::make_shared<const State>(State{c.id(), c.step(), c.position(), c.previousPosition()});
    });
    agents_[static_cast<std::size_t>(i)] = std::move(a);
    if (const std::optional<State> found = recall(i)) {
      agents_[static_cast<std::size_t>(i)]->resume(found->step, found->position, found->previous_position);
    }
    carryOut(i, agents_[static_cast<std::size_t>(i)]->start());
    // Latched topics: the new subscriber gets each neighbour's newest state and the progress.
    for (int j : agents_[static_cast<std::size_t>(i)]->agent().neighbourIds()) {
      if (latched_.count(j)) send({Message::Kind::State, i, latched_[j], {}, -1, false, j});
    }
    if (latchedProgress_) send({Message::Kind::Progress, i, {}, *latchedProgress_, -1, false, -1});
  }
  void agentGotState(int i, const State& s) {
    if (AgentProtocol* a = agents_[static_cast<std::size_t>(i)].get()) {
      // As AgentNode reads its inbox: one Ready, reused (carryOut only queues messages).
      a->step(AgentProtocol::StateArrived{s.id, std::make_shared<const State>(s)}, readyForStates_);
      carryOut(i, readyForStates_);
    }
  }
  void agentGotProgress(int i, const Progress& p) {
    if (AgentProtocol* a = agents_[static_cast<std::size_t>(i)].get()) {
      AgentProtocol::ProgressArrived heard;  // no commands in these runs
      heard.progress.progress = p;
      heard.message = p;
      carryOut(i, a->step(heard));
    }
  }

  void startMonitor() {
    monitor_ = std::make_unique<Referee>(scenario_, window_, true, false);
    std::vector<protocol::ProgressAnswer> answers(agents_.size());
    std::vector<std::vector<State>> histories(agents_.size());
    for (std::size_t i = 0; i < agents_.size(); ++i) {
      if (!agents_[i]) continue;
      const Progress& heard = agents_[i]->lastProgress();
      answers[i] = {true, agents_[i]->hasProgress(), heard.completedStep, heard.convergedStep};
      histories[i] = held(*agents_[i], static_cast<int>(i));
    }
    monitorDo(monitor_->step(Referee::Resume{answers, histories}));
    // Latched: the agents' newest states and the recorder's progress reach the new subscriber.
    for (const auto& l : latched_) send({Message::Kind::State, Message::Monitor, l.second, {}, -1, false, l.first});
    if (recorderReported_ >= 0) send({Message::Kind::RecorderProgress, Message::Monitor, {}, {}, recorderReported_, recorderFinished_, -1});
    publishProgress();
    monitorUpdate();
  }
  void monitorGotState(int i, const State& s) {
    const auto receipt = monitor_->offerState(i, s);
    if (receipt == FormationMonitor::Receipt::Accepted) monitorUpdate();
  }
  void monitorUpdate() { monitorDo(monitor_->step(Referee::Update{true})); }
  /// Carries out what the monitor's referee said, as LockstepMonitor does: each published step is
  /// checked against the centralised run and goes to the recorder; then the progress, the end.
  void monitorDo(const Referee::Ready& r) {
    for (const FormationSnapshot& snap : r.publish) {
      const long k = snap.metrics.step;
      if (!(snap.positions.array() == expected_[static_cast<std::size_t>(k)].array()).all()) {
        violations_.push_back("the monitor's step " + std::to_string(k) + " differs from the centralised run");
      }
      send({Message::Kind::Status, Message::Recorder, {}, {}, k, false, -1});
      if (needsMarkers(k)) send({Message::Kind::Markers, Message::Recorder, {}, {}, k, false, -1});
      latchedStatus_ = k;
      monitor_->keep(k, k);
    }
    if (r.progress || r.finish) publishProgress();  // the end goes out as the final progress
    if (r.finish && monitor_->progressNow().state == Progress::State::Finished) finished_ = true;
  }
  void trace(const std::string& what) const {
    if (std::getenv("PROTOCOL_TRACE")) {
      std::string line = what + " | monitor " + (monitor_ ? std::to_string(monitor_->completedStep()) : "dead") + " written " +
                         std::to_string(written_) + " agents";
      for (const auto& a : agents_) line += " " + (a ? std::to_string(a->agent().step()) + "/" + std::to_string(a->lastProgress().completedStep) : "x");
      std::fprintf(stderr, "%s\n", line.c_str());
    }
  }
  void publishProgress() {
    latchedProgress_ = monitor_->progressNow();
    trace("progress " + std::to_string(latchedProgress_->completedStep) + " allowed " + std::to_string(latchedProgress_->allowedStep));
    for (int i = 0; i < agentCount(); ++i) send({Message::Kind::Progress, i, {}, *latchedProgress_, -1, false, -1});
    send({Message::Kind::Progress, Message::Recorder, {}, *latchedProgress_, -1, false, -1});
  }
  void monitorCatchUp() {
    const std::vector<int> missing = monitor_->missing();
    if (monitor_->running() && !missing.empty()) {
      for (int i : missing) {
        if (agents_[static_cast<std::size_t>(i)]) monitor_->offerHistory(i, held(*agents_[static_cast<std::size_t>(i)], i));
      }
      for (int i : monitor_->missing()) {
        for (const Neighbour& j : formation_.neighbours(i)) {
          const AgentProtocol* a = agents_[static_cast<std::size_t>(j.agent)].get();
          if (a && a->history(i)) monitor_->offerHistory(i, held(*a, i));
        }
      }
    }
    if (monitor_->recorderLags()) {
      for (const auto& u : monitor_->unrecorded()) {
        send({Message::Kind::Status, Message::Recorder, {}, {}, u.first, false, -1});
        if (needsMarkers(u.first)) send({Message::Kind::Markers, Message::Recorder, {}, {}, u.first, false, -1});
      }
    }
    monitorUpdate();
  }

  void record(int i, const State& s) { recorderDo(recorder_.step(Recorder::StateArrived{i, std::make_shared<const State>(s)})); }
  /// Carries out what the recorder said: each written step is checked (in order, whole, every
  /// state equal to the centralised run) and its progress goes to the monitor.
  void recorderDo(const Recorder::Ready& r) {
    if (!r.failed.empty()) violations_.push_back("the recorder failed: " + r.failed);
    if (recorder_.refused() > 0) violations_.push_back("a new state of a written step");
    maxPending_ = std::max(maxPending_, static_cast<long>(recorder_.steps().pendingSteps() + r.write.size()));
    for (const Recorder::Write& w : r.write) {
      if (w.step.step != written_ + 1) violations_.push_back("step " + std::to_string(w.step.step) + " written out of order");
      written_ = w.step.step;
      const auto& q = expected_[static_cast<std::size_t>(w.step.step)];
      const auto& qPrev = expected_[static_cast<std::size_t>(std::max(0L, w.step.step - 1))];
      for (int i = 0; i < agentCount(); ++i) {
        const State& st = *w.step.states[static_cast<std::size_t>(i)];
        for (int c = 0; c < scenario_.dimension; ++c) {
          if (st.step != w.step.step || st.position[static_cast<std::size_t>(c)] != q(c, i) ||
              (st.step > 0 && st.previous_position[static_cast<std::size_t>(c)] != qPrev(c, i))) {
            violations_.push_back("agent " + std::to_string(i) + "'s step " + std::to_string(w.step.step) +
                                  " differs from the centralised run");
            break;
          }
        }
      }
    }
    if (r.report) {
      recorderReported_ = r.report->completedStep;
      ++recorderReports_;
      recorderFinished_ = r.report->state == Progress::State::Finished;
      send({Message::Kind::RecorderProgress, Message::Monitor, {}, {}, recorderReported_, recorderFinished_, -1});
    }
  }
  void recorderGotProgress(const Progress& p) {
    if (p.state == Progress::State::Failed) failure_ = p.reason;
    recorderDo(recorder_.step(Recorder::MonitorProgress{p}));
  }
  /// The recorder's catch-up timer (a second of its clock per call): the histories of the agents
  /// and the monitor, as the node fetches them.
  void recorderCatchUp() {
    recorderClock_ += 1.0;
    const Recorder::Ready tick = recorder_.step(Recorder::Tick{recorderClock_});
    if (!tick.catchUp) return;
    Recorder::HistoriesArrived answers{recorderClock_, {}};
    for (int i : tick.fetch) {
      if (const AgentProtocol* a = agents_[static_cast<std::size_t>(i)].get()) {
        answers.answers.emplace_back(i, std::vector<StatePtr>(a->history(i)->begin(), a->history(i)->end()));
      }
    }
    for (int i : tick.fetch) {
      if (!monitor_) continue;
      answers.answers.emplace_back(i, std::vector<StatePtr>());
      for (const State& st : monitor_->unrecordedStates(i)) answers.answers.back().second.push_back(std::make_shared<const State>(st));
    }
    recorderDo(recorder_.step(answers));
  }

  Scenario scenario_;
  Formation formation_;
  long window_, markerEvery_;
  std::vector<Positions> expected_;
  std::vector<std::unique_ptr<AgentProtocol>> agents_;
  AgentProtocol::Ready readyForStates_;  // agentGotState's, reused
  std::map<int, State> latched_;  // each agent's newest published state
  long recalledAgain_ = 0;
  long historiesAsked_ = 0;
  std::optional<Progress> latchedProgress_;
  std::unique_ptr<Referee> monitor_;
  Recorder recorder_;
  double recorderClock_ = 0.0;
  long latchedStatus_ = -1, written_ = -1, recorderReported_ = -1, maxPending_ = 0, delivered_ = 0;
  long recorderReports_ = 0;
  bool recorderFinished_ = false, finished_ = false;
  std::string failure_;
  std::vector<Message> inFlight_;
  std::vector<std::string> violations_;
};

}  // namespace vf::test
