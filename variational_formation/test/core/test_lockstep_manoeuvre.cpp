// LockstepAgent under step-stamped commands: agents that receive each command at a different
// moment (but before they pass its step), with states delivered in random order, compute what
// ManoeuvreIntegrator computes with the same schedule, bit for bit. Late, invalid and impossible
// commands are refused without side effects.
#include <gtest/gtest.h>

#include <random>

#include "lockstep_delivery.hpp"
#include "test_support.hpp"
#include "variational_formation_core/agents/lockstep_agent.hpp"
#include "variational_formation_core/manoeuvres/manoeuvre_integrator.hpp"

namespace vf {
namespace {

using test::command;

// Runs the agents of `s`; each agent receives every entry of `broadcast` at a random step of its
// own between (entry step - 40) and the entry step. Compares every q_k with `expected`.
void runDistributed(const Scenario& s, const CommandSchedule& broadcast, const CommandSchedule& expectedSchedule,
                    unsigned seed) {
  const std::vector<Positions> expected = test::manoeuvreTrajectory(s, expectedSchedule);
  std::mt19937 rng(seed);
  std::vector<LockstepAgent> agents;
  std::vector<std::vector<long>> deliverAt(static_cast<std::size_t>(s.agentCount()));
  for (int i = 0; i < s.agentCount(); ++i) {
    agents.emplace_back(s, i);
    for (const auto& entry : broadcast.entries()) {
      std::uniform_int_distribution<long> when(std::max(0L, entry.first - 40), entry.first);
      deliverAt[static_cast<std::size_t>(i)].push_back(when(rng));
    }
  }
  std::vector<std::size_t> delivered(agents.size(), 0);
  const auto deliverDue = [&](LockstepAgent& a) {
    std::size_t& next = delivered[static_cast<std::size_t>(a.id())];
    // In order: a command is never overtaken by an older one (the monitor's latched topic).
    while (next < broadcast.entries().size() && deliverAt[static_cast<std::size_t>(a.id())][next] <= a.step()) {
      const auto& entry = broadcast.entries()[next++];
      ASSERT_EQ(a.receiveCommand(entry.first, entry.second), LockstepAgent::CommandReceipt::Accepted);
    }
  };
  long checked = 0;
  test::runInRandomOrder(agents, expected, rng, s.name, &checked, deliverDue);
  EXPECT_EQ(checked, s.steps * s.agentCount());
}

TEST(LockstepManoeuvre, StepStampedCommandsReproduceTheCentralisedRunBitForBit) {
  Scenario s = loadScenario(test::configPath("hexagon_manoeuvre"));
  s.steps = 700;
  s.manoeuvre.clear();
  CommandSchedule commands;
  commands.add(0, command({0.5, 0, 0}, {0, 0, 0}, 1.0));
  commands.add(150, command({0.5, 0.5, 0}, {0, 0, 0.4}, 1.0));
  commands.add(151, command({0.5, 0.5, 0}, {0, 0, 0.4}, 1.3));
  commands.add(400, command({0, -1, 0}, {0, 0, -0.2}, 0.8));
  runDistributed(s, commands, commands, 7);

  Scenario t = loadScenario(test::configPath("tetrahedron"));
  t.steps = 300;
  CommandSchedule turns;
  turns.add(20, command({0.1, 0.2, 0.3}, {0.3, -0.2, 0.5}, 1.2));
  turns.add(200, command({0, 0, 0}, {0, 0.4, 0}, 1.0));
  runDistributed(t, turns, turns, 8);
}

TEST(LockstepManoeuvre, TheScenarioScheduleRunsWithoutAnyCommandAndACommandReplacesItFromItsStep) {
  Scenario s = loadScenario(test::configPath("hexagon_manoeuvre"));
  s.steps = 1200;
  const CommandSchedule scenarioSchedule = scheduleFromSegments(s.manoeuvre, s.timeStep);
  runDistributed(s, CommandSchedule{}, scenarioSchedule, 9);
  // A command at step 500 replaces the scenario's entries from 500 on (the one at 1000 here).
  CommandSchedule override;
  override.add(500, command({0, 0, 0}, {0, 0, 0.3}, 1.1));
  CommandSchedule expected;
  for (const auto& e : scenarioSchedule.entries()) {
    if (e.first < 500) expected.add(e.first, e.second);
  }
  expected.add(500, override.entries()[0].second);
  // The scenario has an entry at step 1000 (t = 10 s), inside the run: the override must drop it.
  ASSERT_EQ(scenarioSchedule.entries()[2].first, 1000);
  runDistributed(s, override, expected, 10);
}

TEST(LockstepManoeuvre, LateInvalidAndImpossibleCommandsAreRefusedWithoutSideEffects) {
  Scenario s = loadScenario(test::configPath("hexagon_manoeuvre"));
  s.manoeuvre.clear();
  LockstepAgent a(s, 0);
  // Step the agent on its own by feeding it its neighbours' initial states: only to step 1.
  for (int j : a.neighbourIds()) {
    const std::vector<double> q(s.initialPositions.col(j).data(), s.initialPositions.col(j).data() + 2);
    ASSERT_EQ(a.receive(j, 0, q, q), LockstepAgent::Receipt::Accepted);
  }
  a.advance();
  ASSERT_EQ(a.step(), 1);
  std::string why;
  EXPECT_EQ(a.receiveCommand(0, command({1, 0, 0}, {0, 0, 0}, 1.0)), LockstepAgent::CommandReceipt::Late);
  EXPECT_EQ(a.receiveCommand(5, command({1, 0, 0.5}, {0, 0, 0}, 1.0), &why), LockstepAgent::CommandReceipt::Invalid);
  EXPECT_NE(why.find("command.velocity: a 2D formation has no z velocity"), std::string::npos) << why;
  EXPECT_EQ(a.receiveCommand(5, command({1, 0, 0}, {0, 0, 0}, -1.0), &why), LockstepAgent::CommandReceipt::Invalid);
  EXPECT_EQ(a.receiveCommand(5, command({NAN, 0, 0}, {0, 0, 0}, 1.0), &why), LockstepAgent::CommandReceipt::Invalid);
  EXPECT_TRUE(a.commands().empty());
  EXPECT_EQ(a.receiveCommand(1, command({1, 0, 0}, {0, 0, 0}, 1.0)), LockstepAgent::CommandReceipt::Accepted);
  EXPECT_EQ(a.commands().entries().size(), 1u);

  // An agent whose edges miss its centroid offset may translate and scale but not turn.
  Positions shape(2, 4);
  shape << 0, 1, 0, 1.2, 0, 0, 1, 0.7;
  Scenario hanging = s;
  hanging.desiredPositions = shape;
  hanging.initialPositions = shape;
  hanging.initialVelocities = Velocities::Zero(2, 4);
  hanging.edges = {{0, 1}, {1, 2}, {2, 0}, {3, 0}};
  LockstepAgent b(hanging, 3);
  EXPECT_EQ(b.receiveCommand(0, command({0, 0, 0}, {0, 0, 0.3}, 1.0), &why), LockstepAgent::CommandReceipt::CannotTurn);
  EXPECT_NE(why.find("agent 3"), std::string::npos) << why;
  EXPECT_EQ(b.receiveCommand(0, command({0.3, 0, 0}, {0, 0, 0}, 1.5)), LockstepAgent::CommandReceipt::Accepted);
}

}  // namespace
}  // namespace vf
