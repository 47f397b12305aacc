// protocol::CommandDesk: which live commands the monitor accepts, the step it stamps them with,
// and the rule that makes every agent apply them at the same step. The randomised test runs the
// lockstep protocol with commands arriving at random moments, lists and progress delivered late
// (in order, per topic), agents killed and resumed, and the monitor restarted from the agents'
// lists, and checks every agent's every step against ManoeuvreIntegrator on the applied schedule,
// bit for bit. The agents are the shipped protocol::AgentProtocol. A failing seed is printed.
#include <gtest/gtest.h>

#include <algorithm>
#include <deque>
#include <memory>
#include <random>

#include "test_support.hpp"
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/agents/lockstep_agent.hpp"
#include "variational_formation_core/manoeuvres/manoeuvre_integrator.hpp"
#include "variational_formation_core/protocol/agent_protocol.hpp"
#include "variational_formation_core/protocol/command_desk.hpp"

namespace vf {
namespace {

using protocol::CommandDesk;
using protocol::IssuedCommand;

Scenario hexagon(long steps) {
  Scenario s = loadScenario(test::configPath("hexagon_manoeuvre"));
  s.manoeuvre.clear();
  s.steps = steps;
  return s;
}

TEST(CommandDesk, RefusesBadCommandsSayingWhy) {
  CommandDesk desk(hexagon(100));
  std::string why;
  EXPECT_FALSE(desk.offerVelocity({NAN, 0, 0}, {0, 0, 0}, why));
  EXPECT_EQ(why, "cmd_vel.velocity: must be finite");
  EXPECT_FALSE(desk.offerVelocity({0, 0, 0.5}, {0, 0, 0}, why));
  EXPECT_EQ(why.rfind("cmd_vel.velocity: a 2D formation has no z velocity", 0), 0u) << why;
  EXPECT_FALSE(desk.offerVelocity({0, 0, 0}, {0.1, 0, 0}, why));
  EXPECT_EQ(why.rfind("cmd_vel.angular_rate: a 2D formation turns about z only", 0), 0u) << why;
  EXPECT_FALSE(desk.offerScale(0.0, why));
  EXPECT_EQ(why, "scale.scale: must be finite and > 0, got 0");
  EXPECT_FALSE(desk.offerScale(-1.0, why));
  EXPECT_FALSE(desk.pending());
  EXPECT_FALSE(desk.issue(10));
  EXPECT_TRUE(desk.issued().empty());
}

TEST(CommandDesk, RefusesTurningAFormationThatCannotTurn) {
  // Agent 3 hangs on one edge: it cannot know its offset from the centroid, so the formation
  // may translate and scale but not turn.
  Scenario s = hexagon(100);
  Positions shape(2, 4);
  shape << 0, 1, 0, 1.2, 0, 0, 1, 0.7;
  s.desiredPositions = shape;
  s.initialPositions = shape;
  s.initialVelocities = Velocities::Zero(2, 4);
  s.edges = {{0, 1}, {1, 2}, {2, 0}, {3, 0}};
  CommandDesk desk(s);
  std::string why;
  EXPECT_FALSE(desk.offerVelocity({0, 0, 0}, {0, 0, 0.3}, why));
  EXPECT_EQ(why.rfind("angular_rate: ", 0), 0u) << why;
  EXPECT_NE(why.find("agent 3"), std::string::npos) << why;
  EXPECT_FALSE(desk.pending());
  EXPECT_TRUE(desk.offerVelocity({0.2, 0, 0}, {0, 0, 0}, why)) << why;
  EXPECT_TRUE(desk.offerScale(1.5, why)) << why;
}

TEST(CommandDesk, StampsAtTheAllowedStepOncePerStepAndMergesWhatWaits) {
  CommandDesk desk(hexagon(1000));
  std::string why;
  ASSERT_TRUE(desk.offerVelocity({0.5, 0, 0}, {0, 0, 0.2}, why)) << why;
  ASSERT_TRUE(desk.issue(40));
  ASSERT_EQ(desk.issued().size(), 1u);
  EXPECT_EQ(desk.issued()[0].first, 40);
  EXPECT_EQ(desk.issued()[0].second, test::command({0.5, 0, 0}, {0, 0, 0.2}, 1.0));
  // Before the allowed step moves, a new input waits; then both halves go out merged.
  ASSERT_TRUE(desk.offerScale(1.5, why));
  EXPECT_FALSE(desk.issue(40));
  ASSERT_TRUE(desk.offerVelocity({0, 0.3, 0}, {0, 0, 0}, why));
  EXPECT_TRUE(desk.pending());
  ASSERT_TRUE(desk.issue(65));
  EXPECT_EQ(desk.issued()[1], IssuedCommand(65, test::command({0, 0.3, 0}, {0, 0, 0}, 1.5)));
  // Only the scale: the velocity in force at that step is kept.
  ASSERT_TRUE(desk.offerScale(0.8, why));
  ASSERT_TRUE(desk.issue(90));
  EXPECT_EQ(desk.issued()[2], IssuedCommand(90, test::command({0, 0.3, 0}, {0, 0, 0}, 0.8)));
  EXPECT_FALSE(desk.pending());
  EXPECT_EQ(desk.schedule().at(89), desk.issued()[1].second);
  EXPECT_EQ(desk.schedule().at(1000), desk.issued()[2].second);
}

TEST(CommandDesk, TheScenarioScheduleIsKeptUntilACommandReplacesItFromItsStep) {
  const Scenario s = loadScenario(test::configPath("hexagon_manoeuvre"));
  const CommandSchedule own = scheduleFromSegments(s.manoeuvre, s.timeStep);
  ASSERT_GE(own.entries().size(), 2u);
  const long second = own.entries()[1].first;
  CommandDesk desk(s);
  std::string why;
  ASSERT_TRUE(desk.offerScale(2.0, why));
  ASSERT_TRUE(desk.issue(second - 10));
  // The command keeps the scenario's velocity at that step and drops its later entries.
  const Command& c = desk.issued()[0].second;
  EXPECT_EQ(c.velocity, own.at(second - 10).velocity);
  EXPECT_EQ(c.scale, 2.0);
  EXPECT_EQ(desk.schedule().at(second + 100), c);
  EXPECT_EQ(desk.schedule().at(second - 11), own.at(second - 11));
  const CommandSchedule applied = protocol::appliedSchedule(s, desk.issued());
  EXPECT_EQ(applied.entries(), desk.schedule().entries());
}

TEST(CommandDesk, ARestartedMonitorGoesOnFromWhatWasIssued) {
  CommandDesk before(hexagon(1000));
  std::string why;
  for (long step : {10L, 30L, 50L}) {
    ASSERT_TRUE(before.offerScale(1.0 + step / 100.0, why));
    ASSERT_TRUE(before.issue(step));
  }
  const std::vector<IssuedCommand> all = before.issued();
  CommandDesk after(hexagon(1000));
  after.resume(all);
  EXPECT_EQ(after.issued(), all);
  EXPECT_EQ(after.schedule().entries(), before.schedule().entries());
  ASSERT_TRUE(after.offerScale(3.0, why));
  EXPECT_FALSE(after.issue(50));  // never at or before the last issued step
  EXPECT_TRUE(after.issue(51));
}

TEST(CommandDesk, SaturatesToTheLimitsAndWarnsAsAScenarioWould) {
  // hexagon_manoeuvre: h = 0.01, kappa = 4; half the softest mode's frequency is 0.96 rad/s at
  // s = 1 (doc/manoeuvres.md), and the stiffest mode is 10 rad/s.
  protocol::CommandLimits limits;
  limits.maxSpeed = 2.0;
  limits.maxTurnRate = 1.0;
  limits.minScale = 0.5;
  limits.maxScale = 2.0;
  CommandDesk desk(hexagon(100), limits);
  std::string why, note;
  ASSERT_TRUE(desk.offerVelocity({0.5, 0, 0}, {0, 0, 0.2}, why, &note)) << why;
  EXPECT_EQ(note, "");
  EXPECT_EQ(desk.saturated(), 0);
  ASSERT_TRUE(desk.offerVelocity({1000, 0, 0}, {0, 0, 3}, why, &note)) << why;  // the issue's 1000 m/s
  EXPECT_NE(note.find("|v*| = 1000 m/s saturated to ~max_speed = 2 m/s"), std::string::npos) << note;
  EXPECT_NE(note.find("|omega*| = 3 rad/s saturated to ~max_turn_rate = 1 rad/s"), std::string::npos) << note;
  EXPECT_NE(note.find("above half the softest shape mode's frequency"), std::string::npos) << note;
  EXPECT_EQ(note.find('\n'), std::string::npos);
  EXPECT_EQ(desk.saturated(), 1);
  ASSERT_TRUE(desk.issue(5));
  EXPECT_NEAR(desk.issued().back().second.velocity.x(), 2.0, 1e-12);
  EXPECT_NEAR(desk.issued().back().second.angularRate.z(), 1.0, 1e-12);
  // A turn of more than 0.1 rad per step is refused, not saturated.
  EXPECT_FALSE(desk.offerVelocity({0, 0, 0}, {0, 0, 20}, why, &note));
  EXPECT_NE(why.find("cmd_vel.angular_rate"), std::string::npos) << why;
  ASSERT_TRUE(desk.offerScale(5.0, why, &note)) << why;
  EXPECT_NE(note.find("s = 5 saturated to ~max_scale = 2"), std::string::npos) << note;
  ASSERT_TRUE(desk.offerScale(0.1, why, &note)) << why;
  EXPECT_NE(note.find("s = 0.1 saturated to ~min_scale = 0.5"), std::string::npos) << note;
  // At s = 0.5 the rate of 1 rad/s issued above is more above half the softest frequency.
  EXPECT_NE(note.find("rad/s at scale 0.5"), std::string::npos) << note;
  EXPECT_EQ(desk.saturated(), 3);
  ASSERT_TRUE(desk.issue(6));
  EXPECT_EQ(desk.issued().back().second.scale, 0.5);
}

TEST(CommandDesk, RefusesAScaleBeyondTheStabilityLimitAndBadLimits) {
  CommandDesk desk(hexagon(100));  // no limits: only stability refuses
  std::string why;
  EXPECT_TRUE(desk.offerScale(10.0, why)) << why;  // 100 rad/s: stable below about 0.02 s
  EXPECT_FALSE(desk.offerScale(50.0, why));
  EXPECT_EQ(why.rfind("scale: s = 50 puts h = 0.01 s above the linear stability limit", 0), 0u) << why;
  protocol::CommandLimits bad;
  bad.maxSpeed = 0.0;
  EXPECT_THROW(CommandDesk(hexagon(100), bad), InvalidInput);
  bad = protocol::CommandLimits();
  bad.minScale = 2.0;
  bad.maxScale = 1.0;
  try {
    protocol::validateCommandLimits(bad);
    ADD_FAILURE() << "no exception";
  } catch (const InvalidInput& e) {
    EXPECT_EQ(std::string(e.what()), "~max_scale: must be >= ~min_scale = 2, got 1");
  }
}

// The lockstep protocol with live commands, driven by one seed (see the file comment): the
// shipped agents (protocol::AgentProtocol, as AgentNode runs it) and a CommandDesk as the
// monitor's, joined by per-agent topics that deliver late, each in order.
struct CommandWorld {
  struct State {
    int id;
    long step;
    std::vector<double> position, previous_position;
  };
  using StatePtr = std::shared_ptr<const State>;
  using Agent = protocol::AgentProtocol<StatePtr, protocol::AgentProgress>;

  Scenario s;
  std::mt19937 rng;
  long window;
  std::vector<std::unique_ptr<Agent>> agents;
  std::vector<StatePtr> latched;  // each agent's newest published state
  std::vector<std::vector<std::vector<double>>> computed;  // each agent's q_k, by step
  // Per agent, what the topics still have to deliver, in order: its neighbours' states,
  // (allowed step, command count) progress messages, and whole lists.
  std::vector<std::deque<StatePtr>> statesInFlight;
  std::vector<std::deque<std::pair<long, long>>> progressInFlight;
  std::vector<std::deque<std::vector<IssuedCommand>>> listsInFlight;
  std::unique_ptr<CommandDesk> desk;
  long allowed = 0;

  CommandWorld(Scenario scenario, unsigned seed, long w) : s(std::move(scenario)), rng(seed), window(w) {
    desk = std::make_unique<CommandDesk>(s);
    const auto n = static_cast<std::size_t>(s.agentCount());
    agents.resize(n);
    latched.resize(n);
    computed.resize(n);
    statesInFlight.resize(n);
    progressInFlight.resize(n);
    listsInFlight.resize(n);
    for (int i = 0; i < s.agentCount(); ++i) {
      agents[static_cast<std::size_t>(i)] = makeAgent(i);
      carryOut(static_cast<std::size_t>(i), agents[static_cast<std::size_t>(i)]->start());
    }
  }
  std::unique_ptr<Agent> makeAgent(int i) const {
    return std::make_unique<Agent>(LockstepAgent(s, i), [](const LockstepAgent& a, const std::string&) {
      return std::make_shared<const State>(State{a.id(), a.step(), a.position(), a.previousPosition()});
    });
  }
  bool chance(double p) { return std::uniform_real_distribution<double>(0.0, 1.0)(rng) < p; }
  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }

  // What agent i's protocol said: each new state is checked against the same step computed
  // before (a resumed agent recomputes it) and goes to its neighbours.
  void carryOut(std::size_t i, const Agent::Ready& ready) {
    ASSERT_EQ(ready.failed, "") << "agent " << i;
    for (const StatePtr& state : ready.publish) {
      auto& q = computed[i];
      if (static_cast<long>(q.size()) == state->step) q.push_back(state->position);
      ASSERT_EQ(q[static_cast<std::size_t>(state->step)], state->position) << "agent " << i << " redid step "
                                                                            << state->step << " differently";
      latched[i] = state;
      for (int j : agents[i]->agent().neighbourIds()) statesInFlight[static_cast<std::size_t>(j)].push_back(state);
    }
  }

  // The monitor: what it publishes, list first, then the progress that counts it.
  void publish() {
    for (auto& q : listsInFlight) q.push_back(desk->issued());
    for (auto& q : progressInFlight) q.emplace_back(allowed, static_cast<long>(desk->issued().size()));
  }
  long completed() const {
    long c = s.steps;
    for (const auto& a : agents) c = std::min(c, a->agent().step());
    return c;
  }
  void monitorTick() {
    if (chance(0.3)) {
      std::string why;
      if (chance(0.5)) {
        desk->offerVelocity({uniform(-1, 1), uniform(-1, 1), 0}, {0, 0, chance(0.5) ? uniform(-0.5, 0.5) : 0.0}, why);
      } else {
        desk->offerScale(uniform(0.7, 1.5), why);
      }
    }
    const long next = std::min(completed() + window, s.steps);
    if (desk->issue(allowed) || next > allowed) {
      allowed = std::max(allowed, next);
      publish();
    }
  }
  // The monitor keeps what it issued on the parameter server before it publishes it: a new one
  // goes on from there (what was pending, not issued yet, is gone with it).
  void restartMonitor() {
    const std::vector<IssuedCommand> kept = desk->issued();
    desk = std::make_unique<CommandDesk>(s);
    desk->resume(kept);
    publish();
  }
  void deliver(std::size_t i) {
    Agent& a = *agents[i];
    while (!listsInFlight[i].empty() && chance(0.6)) {
      const std::vector<IssuedCommand> list = listsInFlight[i].front();
      listsInFlight[i].pop_front();
      carryOut(i, a.step(Agent::CommandsArrived{static_cast<long>(list.size()),
                                                [&list](long k) { return list[static_cast<std::size_t>(k)]; }}));
      if (::testing::Test::HasFatalFailure()) return;
    }
    while (!progressInFlight[i].empty() && chance(0.6)) {
      protocol::AgentProgress p;
      p.progress.state = protocol::Progress::State::Running;
      p.progress.allowedStep = progressInFlight[i].front().first;
      // A restarted monitor may count fewer (a command the monitor before it issued, which no
      // agent received, is gone with it): the newest progress's count holds.
      p.commands = progressInFlight[i].front().second;
      progressInFlight[i].pop_front();
      carryOut(i, a.step(Agent::ProgressArrived{p, p}));
      if (::testing::Test::HasFatalFailure()) return;
    }
    while (!statesInFlight[i].empty() && chance(0.7)) {
      const StatePtr state = statesInFlight[i].front();
      statesInFlight[i].pop_front();
      carryOut(i, a.step(Agent::StateArrived{state->id, state}));
      if (::testing::Test::HasFatalFailure()) return;
    }
  }
  // An agent killed and resumed from its own newest state, with no command and no progress: the
  // latched topics give it its neighbours' newest states, the newest list and progress again.
  void kill(std::size_t i) {
    const StatePtr own = latched[i];
    agents[i] = makeAgent(static_cast<int>(i));
    agents[i]->resume(own->step, own->position, own->previous_position);
    carryOut(i, agents[i]->start());
    statesInFlight[i].clear();
    for (int j : agents[i]->agent().neighbourIds()) statesInFlight[i].push_back(latched[static_cast<std::size_t>(j)]);
    progressInFlight[i].assign(1, {allowed, static_cast<long>(desk->issued().size())});
    listsInFlight[i].assign(1, desk->issued());
  }
};

void runCommandWorld(const Scenario& scenario, unsigned seed, long window, bool faults) {
  SCOPED_TRACE("seed " + std::to_string(seed) + " (test_command_desk --gtest_filter=*Random*)");
  CommandWorld w(scenario, seed, window);
  w.publish();
  for (long tick = 0; tick < 200000 && w.completed() < w.s.steps; ++tick) {
    w.monitorTick();
    if (faults && w.chance(0.002)) w.restartMonitor();
    for (std::size_t i = 0; i < w.agents.size(); ++i) {
      w.deliver(i);
      if (faults && w.chance(0.003)) w.kill(i);
      if (::testing::Test::HasFatalFailure()) return;
    }
  }
  ASSERT_EQ(w.completed(), w.s.steps) << "the run stalled at step " << w.completed();
  const CommandSchedule schedule = protocol::appliedSchedule(w.s, w.desk->issued());
  const Formation formation = makeFormation(w.s);  // the integrator keeps a reference to it
  ManoeuvreIntegrator reference(formation, w.s.initialPositions, w.s.initialVelocities, w.s.timeStep,
                                w.s.dampingGain, StartMethod::Variational, schedule);
  for (long k = 1; k <= w.s.steps; ++k) {
    reference.step();
    for (std::size_t i = 0; i < w.agents.size(); ++i) {
      for (int c = 0; c < w.s.dimension; ++c) {
        ASSERT_EQ(w.computed[i][static_cast<std::size_t>(k)][static_cast<std::size_t>(c)],
                  reference.positions()(c, static_cast<long>(i)))
            << "agent " << i << " step " << k << "; " << w.desk->issued().size() << " commands issued";
      }
    }
  }
  ASSERT_GT(w.desk->issued().size(), 0u);
}

TEST(CommandDesk, RandomInterleavingsEqualTheCentralisedRunBitForBit) {
  for (unsigned seed = 1; seed <= 60; ++seed) {
    runCommandWorld(hexagon(240), seed, 1 + seed % 12, false);
    if (::testing::Test::HasFatalFailure()) return;
  }
}

TEST(CommandDesk, RandomInterleavingsWithKillsAndMonitorRestartsEqualTheCentralisedRun) {
  for (unsigned seed = 100; seed < 160; ++seed) {
    runCommandWorld(hexagon(240), seed, 1 + seed % 12, true);
    if (::testing::Test::HasFatalFailure()) return;
  }
  Scenario t = loadScenario(test::configPath("tetrahedron"));
  t.steps = 150;
  for (unsigned seed = 200; seed < 220; ++seed) {
    runCommandWorld(t, seed, 5, true);
    if (::testing::Test::HasFatalFailure()) return;
  }
}

}  // namespace
}  // namespace vf
