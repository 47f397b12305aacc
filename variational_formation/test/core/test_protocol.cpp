// The distributed protocol without a transport (core/protocol): the run referee, the whole-step
// assembler and the recovery choice, first in the event sequences of failures that rostests
// once found, then in seeded random interleavings of deliveries, repeats, reorderings, losses,
// kills and restarts. Every run must record each state once, equal bit for bit to the
// centralised run, and finish; a run that stalls must say what it waits for.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>
#include <sstream>

#include "protocol_world.hpp"
#include "test_support.hpp"
#include "variational_formation_core/protocol/timed_referee.hpp"
#include "variational_formation/tools/make_scenario_cli.hpp"

namespace vf {
namespace {

using test::Message;
using test::World;
using test::AgentProtocol;
using test::State;

Scenario shortScenario(const std::string& name, long steps) {
  Scenario s = loadScenario(test::configPath(name));
  s.steps = steps;
  return s;
}

/// A scenario as `make_scenario ARGS` writes it.
Scenario generated(std::vector<std::string> args) {
  const std::string path = testing::TempDir() + "protocol_generated.yaml";
  args.insert(args.begin(), "make_scenario");
  args.insert(args.end(), {"--out", path});
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  EXPECT_EQ(runMakeScenarioCli(static_cast<int>(argv.size()), argv.data(), out, err), 0) << err.str();
  return loadScenario(path);
}

/// Delivers everything in order, running the stall timers when nothing is in flight.
/// @return false if the run stalled (20 timer rounds without a new step written).
bool runInOrder(World& w, long maxRounds = 20) {
  long idle = 0;
  while (!w.finished() && !w.failed()) {
    if (w.inFlight().empty()) {
      const long before = w.writtenThrough();
      w.stallTimers();
      if (w.writtenThrough() == before && w.inFlight().empty() && ++idle > maxRounds) return false;
      continue;
    }
    w.deliver(0);
  }
  while (!w.inFlight().empty()) w.deliver(0);  // the recorder's last steps
  return true;
}

void expectComplete(const World& w, long steps) {
  EXPECT_TRUE(w.finished()) << w.waitingFor();
  EXPECT_EQ(w.writtenThrough(), steps) << w.waitingFor();
  for (const std::string& v : w.violations()) ADD_FAILURE() << v;
}

// ---- the recovery choice and the buffers ----

TEST(Recovery, AgentResumesFromTheNewestHolderAndTheFirstOnATie) {
  using protocol::RecallAnswer;
  EXPECT_EQ(protocol::chooseAgentResume({}), -1);
  EXPECT_EQ(protocol::chooseAgentResume({{true, true, 0}, {false, true, 9}}), -1);  // step 0 or unanswered
  EXPECT_EQ(protocol::chooseAgentResume({{true, true, 4}, {true, false, 9}, {true, true, 7}, {true, true, 7}}), 2);
}

// A restarted agent's holders may answer before the dead incarnation's last states reach them:
// an answer no newer than the agent's own step moves nothing and is a note to log, not a dropped
// state (AgentNode counts dropped ones in its status and the result file). A bad answer is still
// dropped.
TEST(Recovery, AnAnswerThatIsNotNewerIsANoteNotADroppedState) {
  const Scenario s = shortScenario("hexagon", 24);
  AgentProtocol a(LockstepAgent(s, 1), [](const LockstepAgent& c, const std::string&) {
    return std::make_shared<const State>(State{c.id(), c.step(), c.position(), c.previousPosition()});
  });
  ASSERT_EQ(a.start().publish.size(), 1u);  // step 0
  const AgentProtocol::Ready stale = a.step(AgentProtocol::Recalled{});  // step -1: nothing beyond step 0
  EXPECT_TRUE(stale.dropped.empty()) << stale.dropped;
  EXPECT_NE(stale.note.find("is not past step 0; waiting for a newer one"), std::string::npos) << stale.note;
  EXPECT_TRUE(stale.publish.empty());
  EXPECT_EQ(stale.resumedAt, -1);
  EXPECT_EQ(a.agent().step(), 0);
  const AgentProtocol::Ready bad = a.step(AgentProtocol::Recalled{5, {1.0}, {1.0}});  // one coordinate in 2-D
  EXPECT_NE(bad.dropped.find("a recalled state: resume: expected 2 coordinates"), std::string::npos) << bad.dropped;
  EXPECT_TRUE(bad.note.empty()) << bad.note;
  EXPECT_EQ(bad.resumedAt, -1);
  const AgentProtocol::Ready newer = a.step(AgentProtocol::Recalled{5, {1.0, 2.0}, {1.0, 2.0}});
  EXPECT_TRUE(newer.dropped.empty() && newer.note.empty()) << newer.dropped << newer.note;
  EXPECT_EQ(newer.resumedAt, 5);
  EXPECT_EQ(a.agent().step(), 5);
}

// AgentNode reads its inbox into one Ready that it reuses: whatever an earlier event left in it,
// each answer must equal the fresh Ready that step(e) returns for the same event.
TEST(AgentProtocolReady, AReusedReadyAnswersAsAFreshOne) {
  const Scenario s = shortScenario("hexagon", 24);
  const auto make = [](const LockstepAgent& c, const std::string&) {
    return std::make_shared<const State>(State{c.id(), c.step(), c.position(), c.previousPosition()});
  };
  AgentProtocol fresh(LockstepAgent(s, 1), make), reused(LockstepAgent(s, 1), make);
  AgentProtocol::Ready ready;  // every field away from its initial value
  ready.publish.push_back(std::make_shared<const State>(State{9, 9, {0.0, 0.0}, {0.0, 0.0}}));
  ready.failed = ready.dropped = ready.note = ready.over = "left over";
  ready.wakeWhenSensed = ready.recallAgain = true;
  ready.wakeAfter = 3.0;
  ready.resumedAt = 7;
  fresh.start();
  reused.start();
  AgentProtocol::ProgressArrived go;
  go.progress.progress.state = test::Progress::State::Running;
  go.progress.progress.allowedStep = 2;
  fresh.step(go);
  reused.step(go);
  // The neighbours' states of step 0, one from the wrong sender (dropped) and one twice (a
  // duplicate, silent); the last completes step 0, so step 1 is published.
  std::vector<AgentProtocol::StateArrived> events;
  const std::vector<int> neighbours = fresh.agent().neighbourIds();
  ASSERT_GE(neighbours.size(), 2u);
  for (int j : neighbours) {
    const LockstepAgent n(s, j);
    events.push_back({j, std::make_shared<const State>(State{j, 0, n.position(), n.previousPosition()})});
  }
  events.insert(events.begin() + 1, events.front());  // a duplicate
  AgentProtocol::StateArrived forged = events.front();
  forged.topic = neighbours[1];  // agent neighbours[0]'s state on neighbours[1]'s topic
  events.insert(events.begin() + 2, forged);
  long published = 0, dropped = 0;
  for (const AgentProtocol::StateArrived& e : events) {
    const AgentProtocol::Ready want = fresh.step(e);
    reused.step(e, ready);
    ASSERT_EQ(ready.publish.size(), want.publish.size());
    for (std::size_t k = 0; k < want.publish.size(); ++k) {
      EXPECT_EQ(ready.publish[k]->step, want.publish[k]->step);
      EXPECT_EQ(ready.publish[k]->position, want.publish[k]->position);  // bit for bit
    }
    EXPECT_EQ(ready.failed, want.failed);
    EXPECT_EQ(ready.dropped, want.dropped);
    EXPECT_EQ(ready.note, want.note);
    EXPECT_EQ(ready.over, want.over);
    EXPECT_EQ(ready.wakeWhenSensed, want.wakeWhenSensed);
    EXPECT_EQ(ready.wakeAfter, want.wakeAfter);
    EXPECT_EQ(ready.recallAgain, want.recallAgain);
    EXPECT_EQ(ready.resumedAt, want.resumedAt);
    published += static_cast<long>(want.publish.size());
    dropped += want.dropped.empty() ? 0 : 1;
  }
  EXPECT_EQ(published, 1);  // step 1, once the last neighbour's state came
  EXPECT_EQ(dropped, 1);    // the forged one
  EXPECT_EQ(reused.agent().step(), 1);
  EXPECT_EQ(fresh.agent().step(), 1);
  ready.clear();
  const AgentProtocol::Ready initial;
  EXPECT_TRUE(ready.publish.empty() && ready.failed.empty() && ready.dropped.empty() && ready.note.empty() &&
              ready.over.empty());
  EXPECT_EQ(ready.wakeWhenSensed, initial.wakeWhenSensed);
  EXPECT_EQ(ready.wakeAfter, initial.wakeAfter);
  EXPECT_EQ(ready.recallAgain, initial.recallAgain);
  EXPECT_EQ(ready.resumedAt, initial.resumedAt);
}

TEST(Recovery, MonitorResumesAfterTheNewestProgressHeard) {
  const auto r = protocol::chooseMonitorResume({{true, true, 11, 3}, {true, true, 19, -1}, {false, true, 50, 2}}, 8);
  EXPECT_EQ(r.step, 20);
  EXPECT_EQ(r.congruentSince, -1);
  EXPECT_EQ(r.acceptUpTo, 20 + 8 + 2);
  EXPECT_FALSE(protocol::chooseMonitorResume({{true, false, 5, 1}, {true, true, -1, -1}}, 8).resumes());
}

TEST(Recovery, MonitorAgainstTheAgentsOfARunThatIsOverNeitherResumesNorStartsOne) {
  // Agent 1 heard the final progress (finished at step 1500); agent 0 only an earlier one.
  const auto r = protocol::chooseMonitorResume({{true, true, 1100, 40}, {true, true, 1500, 40, true, true}}, 8);
  EXPECT_TRUE(r.over);
  EXPECT_TRUE(r.finished);
  EXPECT_EQ(r.overAt, 1500);
  EXPECT_FALSE(r.resumes());
  const std::string line = protocol::describeOver(r);
  EXPECT_NE(line.find("already over (it finished at step 1500)"), std::string::npos) << line;
  EXPECT_EQ(line.find('\n'), std::string::npos);
  // A failed run is over too; an unanswered call says nothing.
  const auto failed = protocol::chooseMonitorResume({{true, true, 30, -1, true, false}}, 8);
  EXPECT_TRUE(failed.over);
  EXPECT_NE(protocol::describeOver(failed).find("it failed at step 30"), std::string::npos);
  EXPECT_FALSE(protocol::chooseMonitorResume({{false, true, 30, -1, true, true}, {true, true, 12, -1}}, 8).over);
  EXPECT_EQ(protocol::describeOver(protocol::chooseMonitorResume({{true, true, 12, -1}}, 8)), "");
}

TEST(Recovery, WindowIsCheckedAgainstTheRecorderBuffers) {
  EXPECT_EQ(protocol::checkBuffers(100), "");
  const long largest = protocol::maxWindow(protocol::RecorderBuffers());
  EXPECT_EQ(protocol::checkBuffers(largest), "");
  EXPECT_LE(protocol::recorderLead(largest), 1024);
  const std::string line = protocol::checkBuffers(largest + 1);
  EXPECT_NE(line.find("keeps only 1024 steps"), std::string::npos) << line;
  EXPECT_EQ(line.find('\n'), std::string::npos);
  EXPECT_NE(protocol::checkBuffers(50, {40, 1024}).find("queues hold 40"), std::string::npos);
}

// ---- the whole-step assembler ----

TEST(StepAssembler, HandsOutWholeStepsInOrderOnce) {
  protocol::StepAssembler<int, int, int> a(2, [](long k) { return k % 2 == 0; });
  EXPECT_TRUE(a.addState(0, 1, 10));
  EXPECT_TRUE(a.addState(1, 1, 11));
  EXPECT_TRUE(a.addStatus(1, 100));
  EXPECT_TRUE(a.takeWhole().empty());  // step 0 is not whole yet
  EXPECT_FALSE(a.addMarkers(1, 5));    // step 1 needs no markers
  EXPECT_TRUE(a.addState(0, 0, 0));
  EXPECT_FALSE(a.addState(0, 0, 99));  // the first copy counts
  EXPECT_TRUE(a.addState(1, 0, 1));
  EXPECT_TRUE(a.addStatus(0, 50));
  EXPECT_EQ(a.lacking(), "step 0: the markers");
  EXPECT_TRUE(a.addMarkers(0, 7));
  const auto whole = a.takeWhole();
  ASSERT_EQ(whole.size(), 2u);
  EXPECT_EQ(whole[0].step, 0);
  EXPECT_EQ(whole[0].states, (std::vector<int>{0, 1}));
  EXPECT_EQ(whole[0].markers, 7);
  EXPECT_EQ(whole[1].status, 100);
  EXPECT_EQ(a.handedOutThrough(), 1);
  EXPECT_FALSE(a.addStatus(1, 100));  // republished: written once
  EXPECT_EQ(a.lacking(), "step 2: agent 0's state, agent 1's state, the status, the markers");
  EXPECT_EQ(protocol::stepOfStamp(0.30000000000000004, 0.1), 3);
}

TEST(StepAssembler, AWholeStepWaitsForWhatItsStatusCounts) {
  // The recorder's rule (manoeuvre_faults flake): a status counts the commands issued before it,
  // and its step is written only once the recorder holds that many, whichever came first.
  protocol::StepAssembler<int, int, int> a(1, [](long) { return false; });
  std::size_t held = 0;
  const auto commandsHeld = [&held](const protocol::StepAssembler<int, int, int>::Step& s) {
    return held >= static_cast<std::size_t>(s.status);
  };
  for (long k = 0; k < 3; ++k) {
    ASSERT_TRUE(a.addState(0, k, 0));
    ASSERT_TRUE(a.addStatus(k, k == 0 ? 0 : 1));  // steps 1 and 2 count one command
  }
  const auto first = a.takeWhole(commandsHeld);
  ASSERT_EQ(first.size(), 1u);  // step 1 waits for the command list
  EXPECT_EQ(a.handedOutThrough(), 0);
  EXPECT_TRUE(a.takeWhole(commandsHeld).empty());
  held = 1;
  const auto rest = a.takeWhole(commandsHeld);
  ASSERT_EQ(rest.size(), 2u);
  EXPECT_EQ(rest[0].step, 1);
  EXPECT_EQ(a.handedOutThrough(), 2);
}

// ---- the run referee, event by event ----

TEST(LockstepReferee, ProgressGoesOutWhenAgentsMayWaitAtTheAllowedStep) {
  // The throttling rule (commit a83a62b, "a throttling deadlock"): a progress goes out every
  // quarter window only, but also whenever the agents may already wait at the allowed step;
  // without that, agents that reached it idle until the window moved a whole quarter.
  const Scenario s = shortScenario("square", 40);
  test::Referee r(s, 8, true, false);
  const auto offerStep = [&](long k) {
    for (int i = 0; i < s.agentCount(); ++i) {
      test::State st{i, k, std::vector<double>(2, 0.1 * i + k), std::vector<double>(2, 0.1 * i)};
      ASSERT_EQ(r.offerState(i, st), FormationMonitor::Receipt::Accepted);
    }
    for (const auto& snap : r.takeCompleted()) r.keep(snap.metrics.step, snap.metrics.step);
  };
  offerStep(0);
  EXPECT_FALSE(r.updateProgress(true));  // the recorder does not hold step 0 yet
  r.recorderProgress(0, false);
  ASSERT_TRUE(r.updateProgress(true));
  EXPECT_EQ(r.progressNow().allowedStep, 8);
  for (long k = 1; k <= 8; ++k) offerStep(k);  // the agents stop at 8
  r.recorderProgress(1, false);                // allowed 9: less than a quarter window (2) more
  ASSERT_TRUE(r.updateProgress(true)) << "agents wait at step 8 and no progress goes out";
  EXPECT_EQ(r.progressNow().allowedStep, 9);
  EXPECT_EQ(r.progressNow().completedStep, 1);
  r.recorderProgress(2, false);
  EXPECT_FALSE(r.updateProgress(true));  // allowed 10: not a quarter more, and nobody waits at 9 yet
  offerStep(9);
  EXPECT_TRUE(r.updateProgress(true));   // now they do
  EXPECT_EQ(r.progressNow().allowedStep, 10);
  r.recorderProgress(9, false);
  ASSERT_TRUE(r.updateProgress(true));
  EXPECT_EQ(r.progressNow().allowedStep, 17);
  EXPECT_EQ(r.waitingFor("rec"), "step 10 of agent_0, agent_1, agent_2, agent_3");
}

TEST(LockstepReferee, StatesPastTheAllowedStepAndRepeatsAreRefused) {
  const Scenario s = shortScenario("square", 40);
  test::Referee r(s, 8, false, false);
  test::State st{0, 1, {0.0, 0.0}, {0.0, 0.0}};
  EXPECT_EQ(r.offerState(0, st), FormationMonitor::Receipt::ImpossibleStep);  // nothing allowed yet
  st.step = 0;
  EXPECT_EQ(r.offerState(0, st), FormationMonitor::Receipt::Accepted);
  EXPECT_EQ(r.offerState(0, st), FormationMonitor::Receipt::Duplicate);
  EXPECT_EQ(r.newest(0)->step, 0);
  EXPECT_EQ(r.newest(1), nullptr);
  r.fail("agent_1 ended");
  EXPECT_TRUE(r.ended());
  EXPECT_EQ(r.progressNow().reason, "agent_1 ended");
  EXPECT_FALSE(r.updateProgress(true));
}

TEST(TimedReferee, StartsOnceEveryAgentIsHeardAndKeepsTheNewestState) {
  const Scenario s = shortScenario("square", 3);
  protocol::TimedReferee<test::State> r(s, 1.0);
  std::string why;
  EXPECT_FALSE(r.offerState(0, {0, 0, {0.0}, {0.0}}, 0.0, why));
  EXPECT_NE(why.find("wrong dimension"), std::string::npos);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(r.offerState(i, {i, 2, {1.0 * i, 0.0}, {1.0 * i, 0.0}}, 0.0, why));
  EXPECT_TRUE(r.tick(0.1).empty());  // agent 3 not heard
  EXPECT_EQ(r.unheard(), std::vector<int>{3});
  ASSERT_TRUE(r.offerState(3, {3, 3, {0.0, 1.0}, {0.0, 1.0}}, 0.2, why));
  ASSERT_TRUE(r.offerState(3, {3, 1, {9.0, 9.0}, {9.0, 9.0}}, 0.5, why));  // older: ignored while fresh
  ASSERT_EQ(r.tick(0.5).size(), 1u);
  EXPECT_EQ(r.newest(3)->step, 3);
  EXPECT_DOUBLE_EQ(r.dataAge(), 0.5);
  EXPECT_EQ(r.silent(1.1), (std::vector<int>{0, 1, 2}));
  ASSERT_TRUE(r.offerState(3, {3, 1, {9.0, 9.0}, {9.0, 9.0}}, 1.3, why));  // a respawned agent, old state stale
  EXPECT_EQ(r.newest(3)->step, 1);
  EXPECT_FALSE(r.finished());
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(r.offerState(i, {i, 3, {1.0 * i, 0.0}, {1.0 * i, 0.0}}, 1.4, why));
  r.tick(1.5);
  EXPECT_TRUE(r.finished());
}

// Issue 50: every path that meets a non-finite position ends the run as diverged. Agents never
// publish one (they fail with their last good state); one that reaches the recorder anyway fails
// the recording with the divergence line (before, it went into the bag), and the monitor's
// referee ends the run with it.
TEST(RecorderProtocolTest, ANonFiniteStateFailsTheRecordingAsADivergence) {
  const Scenario s = shortScenario("square", 10);
  test::Recorder recorder(4, 16, 10, [](long) { return false; }, [](long) { return 0L; });
  const auto state = [](int id, double x) {
    return std::make_shared<const State>(State{id, 0, {x, 0.0}, {x, 0.0}});
  };
  EXPECT_TRUE(recorder.step(test::Recorder::StateArrived{0, state(0, 1.0)}).failed.empty());
  const test::Recorder::Ready r = recorder.step(test::Recorder::StateArrived{1, state(1, std::nan(""))});
  EXPECT_EQ(r.failed, "agent_1's step 0 is not finite (the run diverged)");
  EXPECT_EQ(r.exit, 1);
  EXPECT_TRUE(r.write.empty());
  ASSERT_TRUE(r.report.has_value());
  EXPECT_EQ(r.report->state, test::Progress::State::Failed);
  test::Referee referee(s, 8, true, false);
  EXPECT_TRUE(referee.step(test::Referee::RecorderReport{-1, false, r.failed, false}).finish);
  EXPECT_EQ(referee.progressNow().reason, "the recorder failed: agent_1's step 0 is not finite (the run diverged)");
}

// ---- whole runs, event by event ----

TEST(ProtocolRun, InOrderDeliveryFinishesWithEveryStateOnce) {
  World w(shortScenario("square", 30), 4, 3);
  ASSERT_TRUE(runInOrder(w)) << w.waitingFor();
  expectComplete(w, 30);
}

TEST(ProtocolRun, RepeatsAtStartUpAreRecordedOnce) {
  World w(shortScenario("hexagon", 20), 8, 1);
  // Every first message delivered twice (a latched state, and the same state again after a reconnect).
  for (std::size_t m = 0; m < w.inFlight().size();) {
    w.deliver(m, true);
    w.deliver(m);
  }
  ASSERT_TRUE(runInOrder(w)) << w.waitingFor();
  expectComplete(w, 20);
}

TEST(ProtocolRun, CatchUpFromHistoriesMakesGoodALostState) {
  World w(shortScenario("square", 20), 4, 1);
  // The monitor and the recorder lose agent 2's step 3 (their connections were coming up): it
  // comes from agent 2's history.
  while (!w.inFlight().empty()) {
    const Message& msg = w.inFlight()[0];
    if (msg.kind == Message::Kind::State && msg.from == 2 && msg.to < 0 && msg.state.step == 3) {
      w.lose(0);
    } else {
      w.deliver(0);
    }
    if (w.referee()->completedStep() >= 2) break;
  }
  for (std::size_t m = 0; m < w.inFlight().size();) {
    const Message& msg = w.inFlight()[m];
    if (msg.kind == Message::Kind::State && msg.from == 2 && msg.to < 0 && msg.state.step == 3) {
      w.lose(m);
    } else {
      ++m;
    }
  }
  ASSERT_TRUE(runInOrder(w)) << w.waitingFor();
  expectComplete(w, 20);
}

TEST(ProtocolRun, IncarnationKilledAgainBeforeTheMonitorGotItsStepComesFromItsNeighbours) {
  World w(shortScenario("square", 20), 4, 1);
  std::mt19937 rng(1);
  // Run to step 5 of agent 1, with everything to the monitor and recorder from agent 1 lost.
  const auto deliverUntil = [&](long step) {
    while (!w.inFlight().empty() && w.referee()->completedStep() < step) {
      const Message& msg = w.inFlight()[0];
      if (msg.kind == Message::Kind::State && msg.from == 1 && msg.to < 0) {
        w.lose(0);
      } else {
        w.deliver(0);
      }
    }
  };
  deliverUntil(3);
  w.killAgent(1, rng, 1.0);
  w.restartAgent(1);  // resumes from its neighbours
  deliverUntil(3);
  w.killAgent(1, rng, 1.0);  // and dies again: its neighbours alone hold its newest steps
  w.restartAgent(1);
  ASSERT_TRUE(runInOrder(w)) << w.waitingFor();
  expectComplete(w, 20);
}

// A loaded machine (CI, hexagon3000 with 20 kills): the killed incarnation's last states reach
// its neighbours only after the new one asked them where to resume. The new one resumes behind,
// its neighbours run on with the dead one's states and come back two steps past it: from that it
// knows a newer state of its own exists, asks again, resumes there and goes on exactly. Without
// Ready::recallAgain the run stalls ("waiting for step k of agent_1").
TEST(ProtocolRun, LateStateOfTheDeadIncarnationMakesTheNewOneRecallAgain) {
  for (const long held : {6L, 11L}) {
    World w(shortScenario("hexagon", 24), 6, 1);
    std::mt19937 rng(2);
    // Delivers the first message `pick` allows until there is none.
    const auto deliverWhile = [&w](const std::function<bool(const Message&)>& pick) {
      for (bool moved = true; moved;) {
        moved = false;
        for (std::size_t k = 0; k < w.inFlight().size() && !moved; ++k) {
          if (pick(w.inFlight()[k])) {
            w.deliver(k);
            moved = true;
          }
        }
      }
    };
    const auto late = [held](const Message& m) { return m.kind == Message::Kind::State && m.from == 1 && m.state.step >= held; };
    deliverWhile([&late](const Message& m) { return !late(m); });  // agent 1's states from step `held` wait
    ASSERT_GE(w.newestAgentStep(), held) << "agent 1 never published step " << held;
    w.killAgent(1, rng, 0.0);                   // what it sent stays in flight
    w.restartAgent(1, /*deliverFirst=*/false);  // its holders answer step held - 1
    // Then the dead one's states arrive; the neighbours run on, and only then do the new one's
    // subscriptions connect: it gets each neighbour's newest (latched) state.
    deliverWhile([](const Message& m) { return m.to != 1; });
    const auto toNewOne = [](const Message& m, int from) { return m.kind == Message::Kind::State && m.to == 1 && m.from == from; };
    for (int j = 0; j < w.agentCount(); ++j) {
      for (std::size_t k = 0; j != 1 && k < w.inFlight().size(); ++k) {
        if (toNewOne(w.inFlight()[k], j)) {
          w.reconnect(k);  // the connection's messages give way to the latched newest
          break;
        }
      }
    }
    ASSERT_TRUE(runInOrder(w)) << w.waitingFor();
    expectComplete(w, 24);
    EXPECT_GE(w.recalledAgain(), 1) << "held from step " << held << ": the late states never put agent 1 behind";
  }
}

// An agent_manager killed while its batch to the monitor lagged behind its agents (the batch
// goes out every 5 ms; a neighbour in the process gets a state at once, and an agent at the
// manager's edge publishes on its own topic at once). Its inner agents' last states then exist
// nowhere, while its edge agents' states computed from them survive in the next manager. The
// restarted inner agents resume behind the edge ones, and no holder has their lost steps; before
// Ready::askNeighbourHistories the run stalled for good ("waiting for a newer state of its own",
// seen in the sharded rostest). Now they compute those steps again from the edge agents' states
// that the other manager's agents hold, and the run ends exactly.
TEST(ProtocolRun, ManagerKilledWithItsBatchUnsentRecomputesTheLostSteps) {
  // A ring with chords: agent i's neighbours are i +- 1 and i +- 2. The manager holds 0 to 5: 2
  // and 3 have every neighbour inside it; 0, 1, 4 and 5 border the other agents.
  const Scenario s = generated({"--shape", "ring", "--agents", "12", "--chords", "1", "--steps", "40"});
  const std::vector<int> manager{0, 1, 2, 3, 4, 5};
  const auto inManager = [&manager](int i) { return std::find(manager.begin(), manager.end(), i) != manager.end(); };
  for (const long lagFrom : {0L, 5L}) {
    World w(s, 20, 1);
    while (!w.inFlight().empty() && w.referee()->completedStep() < lagFrom) w.deliver(0);
    // From here the manager's states reach the monitor and the recorder no more: everything else
    // flows until the window stops the agents.
    const auto batched = [&inManager](const Message& m) {
      return m.kind == Message::Kind::State && inManager(m.from) && m.to < 0;
    };
    for (bool moved = true; moved;) {
      moved = false;
      for (std::size_t k = 0; k < w.inFlight().size() && !moved; ++k) {
        if (!batched(w.inFlight()[k])) {
          w.deliver(k);
          moved = true;
        }
      }
    }
    const long inner = w.newestAgentStep();
    ASSERT_GT(inner, lagFrom + 1) << "the agents never ran ahead of the monitor";
    std::mt19937 rng(3);
    for (int i : manager) w.killAgent(i, rng, 1.0);  // the unsent batch dies with the manager
    for (int i : manager) w.restartAgent(i);
    ASSERT_TRUE(runInOrder(w)) << "lag from step " << lagFrom << ": " << w.waitingFor();
    expectComplete(w, 40);
    EXPECT_GE(w.historiesAsked(), 1) << "lag from step " << lagFrom << ": no step was lost everywhere";
  }
}

TEST(ProtocolRun, MonitorRestartWithIncompleteStepsResumesExactly) {
  World w(shortScenario("hexagon", 24), 6, 2);
  for (int k = 0; k < 150 && !w.inFlight().empty(); ++k) w.deliver(w.inFlight().size() / 2);
  ASSERT_LT(w.referee()->completedStep(), 24);
  w.killMonitor();
  for (int k = 0; k < 30 && !w.inFlight().empty(); ++k) w.deliver(0);  // the agents go on meanwhile
  w.restartMonitor();
  ASSERT_TRUE(runInOrder(w)) << w.waitingFor();
  expectComplete(w, 24);
}

TEST(ProtocolRun, RecorderThatFallsBehindHoldsTheAgentsWithinTheWindow) {
  const long window = 8;
  World w(shortScenario("square", 60), window, 1);
  // Everything but the recorder's messages first: the agents run until the window stops them.
  long idle = 0, lead = 0;
  while (!w.finished() && idle < 1000) {
    std::size_t m = 0;
    while (m < w.inFlight().size() && w.inFlight()[m].to == Message::Recorder) ++m;
    if (m == w.inFlight().size()) {
      if (w.inFlight().empty()) break;
      m = 0;  // only the recorder's are left: it takes one
      ++idle;
    }
    w.deliver(m);
    // The gate: the agents never compute past the recorder's written step plus the window.
    ASSERT_LE(w.newestAgentStep(), w.writtenThrough() + window);
    lead = std::max(lead, w.newestAgentStep() - w.writtenThrough());
  }
  ASSERT_TRUE(runInOrder(w)) << w.waitingFor();
  expectComplete(w, 60);
  EXPECT_EQ(lead, window) << "the recorder never fell a whole window behind";
  EXPECT_LE(w.maxPendingSteps(), protocol::recorderLead(window));
}

/// Delivers every message in order, and never runs a timer. @return false if it stopped short.
bool runWithoutTimers(World& w) {
  while (!w.finished() && !w.failed() && !w.inFlight().empty()) w.deliver(0);
  return w.finished();
}

TEST(ProtocolRun, RecorderReportsEveryFewStepsWithoutEverHoldingTheAgentsBack) {
  // One report per step woke the monitor at every step. Now the recorder reports every
  // kReportEvery whole steps, and at once when the agents may wait for it. With no timer at all
  // (a timer would hide a stall as a half-second pause) both runs must still end.
  const long steps = 200;
  World wide(shortScenario("square", steps), 40, 1);
  ASSERT_TRUE(runWithoutTimers(wide)) << wide.waitingFor();
  expectComplete(wide, steps);
  // Step 0, then every 16th step, then the last: 14 reports, against 201 before.
  EXPECT_LE(wide.recorderReports(), steps / test::Recorder::kReportEvery + 2);
  EXPECT_GE(wide.recorderReports(), steps / test::Recorder::kReportEvery);
  // A window of one step: the agents wait for the recorder at every step, so it reports each.
  World narrow(shortScenario("square", 30), 1, 1);
  ASSERT_TRUE(runWithoutTimers(narrow)) << narrow.waitingFor();
  expectComplete(narrow, 30);
  EXPECT_GE(narrow.recorderReports(), 30);
}

// ---- seeded random interleavings ----

struct Chances {
  double repeat = 0.05, lose = 0.03, killAgent = 0.004, killMonitor = 0.001, restart = 0.05, timers = 0.02;
  /// Events after a restart before the next kill; and the stall timers must have run in between:
  /// one fault at a time, each recovered (see FasterFaults below for what happens otherwise).
  long settle = 50;
};

/// One seeded interleaving. @return "" or what went wrong.
std::string randomRun(const Scenario& s, long window, unsigned seed, const Chances& c) {
  World w(s, window, 1 + seed % 3);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<int> dead;
  bool monitorDead = false;
  long events = 0, idle = 0, lastWritten = -1, settledAt = 0;
  bool timersRan = true;
  while (!w.finished() && !w.failed()) {
    if (++events > 400000) return "no end after 400000 events; waiting for " + w.waitingFor();
    if (!w.violations().empty()) return w.violations().front();
    const double x = u(rng);
    if (monitorDead && (x < c.restart || w.inFlight().empty())) {
      w.restartMonitor();
      monitorDead = false;
      settledAt = events + c.settle;
      timersRan = c.settle == 0;
    } else if (!dead.empty() && (x < c.restart || w.inFlight().empty())) {
      w.restartAgent(dead.back());
      dead.pop_back();
      settledAt = events + c.settle;
      timersRan = c.settle == 0;
    } else if (x < c.killAgent && dead.empty() && !monitorDead && events > settledAt && timersRan) {
      const int i = static_cast<int>(rng() % static_cast<unsigned>(w.agentCount()));
      if (w.agentAlive(i)) {
        w.killAgent(i, rng, 0.5);
        dead.push_back(i);
      }
    } else if (x < c.killAgent + c.killMonitor && dead.empty() && !monitorDead && events > settledAt && timersRan) {
      w.killMonitor();
      monitorDead = true;
    } else if (w.inFlight().empty() || x < c.killAgent + c.killMonitor + c.timers) {
      w.stallTimers();
      timersRan = true;
      if (w.writtenThrough() == lastWritten && w.inFlight().empty() && ++idle > 50) {
        return "stalled at step " + std::to_string(lastWritten) + "; waiting for " + w.waitingFor();
      }
    } else {
      const std::size_t m = rng() % w.inFlight().size();
      const Message& msg = w.inFlight()[m];
      const bool losable = msg.kind == Message::Kind::State || msg.kind == Message::Kind::Status ||
                           msg.kind == Message::Kind::Markers;
      const double y = u(rng);
      if (losable && y < c.lose) {
        w.reconnect(m);
      } else {
        w.deliver(m, y > 1.0 - c.repeat);
      }
    }
    if (w.writtenThrough() != lastWritten) idle = 0;
    lastWritten = w.writtenThrough();
  }
  if (w.failed()) return "the run failed: " + w.failure();
  while (!w.inFlight().empty()) w.deliver(0);
  if (w.writtenThrough() != s.steps) return "finished with steps up to " + std::to_string(w.writtenThrough()) + " written";
  return w.violations().empty() ? "" : w.violations().front();
}

TEST(ProtocolRandom, SeededInterleavingsRecordEveryStateOnceExactly) {
  // The shipped formations, and generated rings and a grid as make_scenario builds them.
  std::vector<std::pair<Scenario, long>> cases;  // scenario, window
  for (const char* name : {"square", "hexagon", "tetrahedron", "grid24"}) cases.push_back({shortScenario(name, 12), 4});
  cases[1].second = 1;
  cases[2].second = 9;
  cases.push_back({generated({"--shape", "ring", "--agents", "9", "--chords", "1", "--steps", "12"}), 3});
  cases.push_back({generated({"--shape", "henneberg", "--agents", "7", "--dimension", "3", "--steps", "12"}), 5});
  long interleavings = 0;
  const unsigned runs = 500;  // per formation
  for (std::size_t c = 0; c < cases.size(); ++c) {
    for (unsigned seed = 1; seed <= runs; ++seed) {
      const unsigned full = static_cast<unsigned>(c) * 100000u + seed;
      if (std::getenv("PROTOCOL_SEED") && std::to_string(full) != std::getenv("PROTOCOL_SEED")) continue;
      const std::string failure = randomRun(cases[c].first, cases[c].second, full, Chances());
      ++interleavings;
      if (!failure.empty()) {
        ADD_FAILURE() << "seed " << full << " (" << cases[c].first.name << ", window " << cases[c].second
                      << "): " << failure;
        std::printf("protocol: failing seed %u\n", full);
      }
    }
  }
  std::printf("protocol: %ld seeded interleavings over %zu formations\n", interleavings, cases.size());
}

}  // namespace
}  // namespace vf
