// The referees' Ready (core/protocol/referee_ready.hpp): what a monitor node must do after each
// event, in order. Timed mode's start, progress throttling, command stamp and end, and in both
// modes the failures the node reports, which only the referee turns into the end of the run.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "test_support.hpp"
#include "variational_formation_core/protocol/lockstep_referee.hpp"
#include "variational_formation_core/protocol/timed_referee.hpp"

namespace vf {
namespace {

using protocol::Progress;

/// An AgentState without ROS: the fields the referees read.
struct State {
  int id = -1;
  long step = -1;
  std::vector<double> position, previous_position;
};
using Timed = protocol::TimedReferee<State>;
using Lockstep = protocol::LockstepReferee<State, long>;

Scenario square(long steps) {
  Scenario s = loadScenario(test::configPath("square"));
  s.steps = steps;
  return s;
}

/// Agent i of the square at step k (any finite positions: the referees only measure them).
State at(int i, long k) { return {i, k, {0.5 * i + 0.01 * k, 0.25 * i}, {0.5 * i, 0.25 * i}}; }

/// Every agent of `r` sends its state at step k.
void offerAll(Timed& r, long k, double now) {
  std::string why;
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(r.offerState(i, at(i, k), now, why)) << why;
}

Timed::Tick tick(double now, bool viewer = false, long lastCommand = -1) { return {now, viewer, lastCommand}; }

/// A Ready that asks for nothing.
void expectEmpty(const protocol::RefereeReady& r) {
  EXPECT_TRUE(r.publish.empty());
  EXPECT_EQ(r.commandsAt, -1);
  EXPECT_FALSE(r.progress);
  EXPECT_FALSE(r.finish);
}

// ---- timed mode ----

TEST(TimedRefereeReady, StartsAtTheFirstTickThatMeasuredEveryAgentThenSaysEveryQuarterWindow) {
  Timed r(square(0), 1.0, 8, false);  // unbounded, a quarter window is 2 ticks
  std::string why;
  ASSERT_TRUE(r.offerState(0, at(0, 0), 0.0, why));
  expectEmpty(r.step(tick(0.0)));  // three agents unheard: the run has not started
  offerAll(r, 0, 0.0);
  Timed::Ready first = r.step(tick(0.1));
  ASSERT_EQ(first.publish.size(), 1u);
  EXPECT_EQ(first.publish[0].metrics.step, 0);
  EXPECT_TRUE(first.progress);
  EXPECT_TRUE(first.starts);
  EXPECT_FALSE(first.finish);
  EXPECT_EQ(r.progressNow().state, Progress::State::Running);
  EXPECT_EQ(r.progressNow().completedStep, 0);
  EXPECT_EQ(r.progressNow().allowedStep, 8);
  // Ticks 1..6: a progress at ticks 2, 4 and 6 only (completed >= the last one's + 2).
  std::vector<long> progressAt;
  for (long k = 1; k <= 6; ++k) {
    const Timed::Ready next = r.step(tick(0.1 + 0.1 * k));
    ASSERT_EQ(next.publish.size(), 1u);
    EXPECT_EQ(next.publish[0].metrics.step, k);
    EXPECT_FALSE(next.starts);
    EXPECT_FALSE(next.finish);
    if (next.progress) progressAt.push_back(k);
  }
  EXPECT_EQ(progressAt, (std::vector<long>{2, 4, 6}));
  EXPECT_EQ(r.progressNow().completedStep, 6);
  EXPECT_EQ(r.progressNow().allowedStep, 14);
}

TEST(TimedRefereeReady, AWindowUnderFourSaysEveryTick) {
  Timed r(square(0), 1.0, 3, false);  // window / 4 = 0: at least every tick
  offerAll(r, 0, 0.0);
  for (long k = 0; k < 4; ++k) EXPECT_TRUE(r.step(tick(0.1 * k)).progress) << "tick " << k;
}

TEST(TimedRefereeReady, AnAwaitedViewerHoldsTheStartButNotTheMeasurement) {
  Timed r(square(0), 1.0, 8, true);
  offerAll(r, 0, 0.0);
  for (long k = 0; k < 3; ++k) {
    const Timed::Ready noViewer = r.step(tick(0.1 * k, false));
    EXPECT_EQ(noViewer.publish.size(), 1u);  // the status goes out: a viewer that comes needs it
    EXPECT_FALSE(noViewer.progress);
    EXPECT_EQ(r.progressNow().state, Progress::State::Waiting);
  }
  const Timed::Ready seen = r.step(tick(0.4, true));
  EXPECT_TRUE(seen.progress);
  EXPECT_TRUE(seen.starts);
  EXPECT_EQ(r.progressNow().completedStep, 3);
}

TEST(TimedRefereeReady, TheTickAtTheLastStepFinishesWithoutAProgressAndNothingFollows) {
  Timed r(square(3), 1.0, 8, false);
  offerAll(r, 0, 0.0);
  for (long k = 0; k < 3; ++k) EXPECT_FALSE(r.step(tick(0.1 * k)).finish) << "tick " << k;
  const Timed::Ready last = r.step(tick(0.3));
  ASSERT_EQ(last.publish.size(), 1u);
  EXPECT_EQ(last.publish[0].metrics.step, 3);
  EXPECT_EQ(last.commandsAt, 4);  // a pending command still goes out before the end
  EXPECT_FALSE(last.progress);
  EXPECT_TRUE(last.finish);
  EXPECT_EQ(r.progressNow().state, Progress::State::Finished);
  EXPECT_EQ(r.progressNow().reason, "");
  expectEmpty(r.step(tick(0.4)));
  expectEmpty(r.step(protocol::Failure{"too late"}));  // an end after the end changes nothing
  EXPECT_EQ(r.progressNow().state, Progress::State::Finished);
}

TEST(TimedRefereeReady, EveryAgentAtTheLastStepFinishesAfterTheProgressOfThatTick) {
  Timed r(square(50), 1.0, 8, false);
  offerAll(r, 50, 0.0);  // the agents are done before the monitor's clock got far
  const Timed::Ready r0 = r.step(tick(0.1));
  EXPECT_TRUE(r0.progress);  // the start goes out, and the end after it
  EXPECT_TRUE(r0.finish);
  EXPECT_EQ(r.progressNow().state, Progress::State::Finished);
  EXPECT_EQ(r.progressNow().completedStep, 0);
}

TEST(TimedRefereeReady, CommandsAreStampedAfterTheTickAndAfterTheNewestIssued) {
  Timed r(square(0), 1.0, 8, false);
  offerAll(r, 0, 0.0);
  EXPECT_EQ(r.step(tick(0.0, false, -1)).commandsAt, 1);  // tick 0 measured: from step 1
  EXPECT_EQ(r.step(tick(0.1, false, 7)).commandsAt, 8);   // one already stamped 7
  EXPECT_EQ(r.commandStep(-1), 2);
}

TEST(TimedRefereeReady, FailuresAndABlockedFormationEndTheRunThroughTheReferee) {
  Timed failed(square(0), 1.0, 8, false);
  offerAll(failed, 0, 0.0);
  failed.step(tick(0.0));
  const Timed::Ready f = failed.step(protocol::Failure{"agent_2 ended before the run was over"});
  EXPECT_TRUE(f.finish);
  EXPECT_TRUE(f.publish.empty());
  EXPECT_FALSE(f.progress);
  EXPECT_EQ(failed.progressNow().state, Progress::State::Failed);
  EXPECT_EQ(failed.progressNow().reason, "agent_2 ended before the run was over");
  expectEmpty(failed.step(tick(0.1)));  // no status after the end
  expectEmpty(failed.step(protocol::Blocked{}));
  EXPECT_EQ(failed.progressNow().state, Progress::State::Failed);

  Timed blocked(square(0), 1.0, 8, false);
  EXPECT_TRUE(blocked.step(protocol::Blocked{}).finish);
  EXPECT_EQ(blocked.progressNow().state, Progress::State::Finished);  // the verdict says blocked
}

// ---- lockstep ----

/// Every agent of `r` sends its state at step k.
void offerAll(Lockstep& r, long k) {
  for (int i = 0; i < 4; ++i) ASSERT_EQ(r.offerState(i, at(i, k)), FormationMonitor::Receipt::Accepted) << "step " << k;
}
/// The Update a node makes after accepted states, with what it keeps for the recorder.
Lockstep::Ready update(Lockstep& r) {
  Lockstep::Ready ready = r.step(Lockstep::Update{true});
  for (const FormationSnapshot& s : ready.publish) r.keep(s.metrics.step, s.metrics.step);
  return ready;
}

TEST(LockstepRefereeReady, StepsThenTheCommandStampThenTheProgress) {
  Lockstep r(square(40), 8, true, false);
  offerAll(r, 0);
  const Lockstep::Ready r0 = update(r);
  ASSERT_EQ(r0.publish.size(), 1u);
  EXPECT_FALSE(r0.progress);  // the recorder does not hold step 0 yet
  EXPECT_EQ(r0.commandsAt, 1);  // not before the allowed step (0), and past the published step 0
  const Lockstep::Ready started = r.step(Lockstep::RecorderReport{0, false, "", true});
  EXPECT_TRUE(started.publish.empty());
  EXPECT_TRUE(started.progress);
  EXPECT_TRUE(started.starts);
  EXPECT_EQ(started.commandsAt, 8);  // the allowed step
  for (long k = 1; k <= 8; ++k) offerAll(r, k);
  const Lockstep::Ready eight = update(r);
  ASSERT_EQ(eight.publish.size(), 8u);
  EXPECT_EQ(eight.publish.front().metrics.step, 1);
  EXPECT_EQ(eight.publish.back().metrics.step, 8);
  // The recorder holds step 0 only: the agents wait at the allowed step 8, which every status
  // is out for: a command goes after them.
  EXPECT_EQ(eight.commandsAt, 9);
  EXPECT_FALSE(eight.starts);
}

TEST(LockstepRefereeReady, TheLastStepFinishesOnceTheRecorderHoldsIt) {
  Lockstep r(square(2), 8, true, false);
  offerAll(r, 0);
  update(r);
  ASSERT_TRUE(r.step(Lockstep::RecorderReport{0, false, "", true}).starts);  // allowed step 2
  for (long k = 1; k <= 2; ++k) offerAll(r, k);
  EXPECT_EQ(update(r).publish.size(), 2u);
  const Lockstep::Ready partial = r.step(Lockstep::RecorderReport{2, false, "", true});
  EXPECT_FALSE(partial.finish);  // every step held, but the recorder has not closed its bag
  const Lockstep::Ready done = r.step(Lockstep::RecorderReport{2, true, "", true});
  EXPECT_TRUE(done.finish);
  EXPECT_FALSE(done.progress);  // the final progress is the node's finish
  EXPECT_EQ(done.commandsAt, -1);
  EXPECT_EQ(r.progressNow().state, Progress::State::Finished);
  expectEmpty(r.step(Lockstep::Update{true}));
}

TEST(LockstepRefereeReady, FailuresEndTheRunOnceWithTheirReason) {
  Lockstep r(square(40), 8, true, false);
  offerAll(r, 0);
  update(r);
  const Lockstep::Ready recorder = r.step(Lockstep::RecorderReport{-1, false, "cannot write the bag", true});
  EXPECT_TRUE(recorder.finish);
  EXPECT_EQ(r.progressNow().state, Progress::State::Failed);
  EXPECT_EQ(r.progressNow().reason, "the recorder failed: cannot write the bag");
  expectEmpty(r.step(protocol::Failure{"/formation/agent_1: step 3 is not finite"}));
  EXPECT_EQ(r.progressNow().reason, "the recorder failed: cannot write the bag");

  Lockstep agent(square(40), 8, false, false);
  offerAll(agent, 0);
  update(agent);
  EXPECT_TRUE(agent.step(protocol::Failure{"/formation/agent_1: step 3 is not finite"}).finish);
  EXPECT_EQ(agent.progressNow().state, Progress::State::Failed);
  EXPECT_EQ(agent.progressNow().reason, "/formation/agent_1: step 3 is not finite");

  Lockstep blocked(square(40), 8, false, false);
  EXPECT_TRUE(blocked.step(protocol::Blocked{}).finish);
  EXPECT_EQ(blocked.progressNow().state, Progress::State::Finished);
}

TEST(LockstepRefereeReady, AResumeOfARunAlreadyOverFinishesItAsFailed) {
  Lockstep r(square(40), 8, false, false);
  // Every agent heard that the run finished at step 40: this monitor did not witness it.
  std::vector<protocol::ProgressAnswer> heard(4, {true, true, 40, -1, true, true});
  const Lockstep::Ready ready = r.step(Lockstep::Resume{heard, std::vector<std::vector<State>>(4)});
  EXPECT_TRUE(ready.finish);
  EXPECT_EQ(r.progressNow().state, Progress::State::Failed);
  EXPECT_FALSE(r.progressNow().reason.empty());

  Lockstep fresh(square(40), 8, false, false);
  const Lockstep::Ready none = fresh.step(Lockstep::Resume{std::vector<protocol::ProgressAnswer>(4),
                                                           std::vector<std::vector<State>>(4)});
  expectEmpty(none);  // a new run: nothing to do, and it waits
  EXPECT_FALSE(fresh.running());
  EXPECT_FALSE(fresh.ended());
}

}  // namespace
}  // namespace vf
