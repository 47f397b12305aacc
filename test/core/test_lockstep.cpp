// LockstepAgent: the distributed protocol without transport. Agents that exchange states in
// any order (with losses made good by later states) reproduce the centralised run bit for bit.
#include <cmath>

#include <gtest/gtest.h>

#include <random>

#include "test_support.hpp"
#include "variational_formation/core/error.hpp"
#include "variational_formation/core/lockstep_agent.hpp"
#include "variational_formation/core/monitor.hpp"
#include "variational_formation/core/variational_integrator.hpp"

namespace vf {
namespace {

struct Message {
  int sender;
  long step;
  std::vector<double> q, qPrev;
};

void runDistributed(const std::string& name, unsigned seed) {
  Scenario s = loadScenario(test::configPath(name));
  s.steps = std::min<long>(s.steps, 300);
  const Formation f = makeFormation(s);
  std::vector<LockstepAgent> agents;
  for (int i = 0; i < s.agentCount(); ++i) agents.emplace_back(s, i);
  VariationalIntegrator reference(f, s.initialPositions, s.initialVelocities, s.timeStep, s.dampingGain,
                                  StartMethod::Variational);
  std::vector<Positions> expected{reference.positions()};
  for (long k = 0; k < s.steps; ++k) {
    reference.step();
    expected.push_back(reference.positions());
  }
  std::mt19937 rng(seed);
  std::vector<Message> inFlight;
  const auto broadcast = [&](const LockstepAgent& a) {
    inFlight.push_back({a.id(), a.step(), a.position(), a.previousPosition()});
  };
  for (const auto& a : agents) broadcast(a);
  long checked = 0;
  while (true) {
    bool allDone = true;
    for (const auto& a : agents) allDone = allDone && a.finished();
    if (allDone) break;
    ASSERT_FALSE(inFlight.empty()) << "deadlock";
    // Deliver a random in-flight state to every agent: states of one sender may overtake each
    // other, and an overtaken one is refused as "going back", a loss that the newer state
    // (which carries q_{m-1}) makes good.
    std::uniform_int_distribution<std::size_t> pick(0, inFlight.size() - 1);
    const std::size_t m = pick(rng);
    const Message msg = inFlight[m];
    inFlight.erase(inFlight.begin() + static_cast<long>(m));
    for (auto& a : agents) {
      a.receive(msg.sender, msg.step, msg.q, msg.qPrev);
      while (!a.finished() && a.ready()) {
        a.advance();
        for (int c = 0; c < s.dimension; ++c) {
          ASSERT_EQ(a.position()[c], expected[static_cast<std::size_t>(a.step())](c, a.id()))
              << name << " agent " << a.id() << " step " << a.step();
        }
        ++checked;
        broadcast(a);
      }
    }
  }
  EXPECT_EQ(checked, s.steps * s.agentCount());
}

TEST(Lockstep, RandomDeliveryOrderReproducesTheCentralisedRunBitForBit) {
  runDistributed("hexagon", 1);
  runDistributed("tetrahedron", 2);
  runDistributed("grid24", 3);
}

TEST(Lockstep, MalformedStatesAreRejectedWithoutSideEffects) {
  const Scenario s = loadScenario(test::configPath("hexagon"));
  LockstepAgent a(s, 0);  // neighbours 1, 5, 2, 3, 4
  const std::vector<double> ok{3.0, 0.0}, bad{1.0};
  using R = LockstepAgent::Receipt;
  EXPECT_EQ(a.receive(0, 0, ok, ok), R::UnknownSender);   // itself
  EXPECT_EQ(a.receive(9, 0, ok, ok), R::UnknownSender);
  EXPECT_EQ(a.receive(1, 0, bad, ok), R::WrongDimension);
  EXPECT_EQ(a.receive(1, 0, {std::nan(""), 0.0}, ok), R::NonFinite);
  EXPECT_EQ(a.receive(1, 0, {HUGE_VAL, 0.0}, ok), R::NonFinite);
  EXPECT_EQ(a.receive(1, 2, ok, ok), R::ImpossibleStep);  // two ahead of us
  EXPECT_EQ(a.receive(1, -1, ok, ok), R::ImpossibleStep);
  EXPECT_FALSE(a.ready());
  EXPECT_EQ(a.receive(1, 1, ok, ok), R::Accepted);        // one ahead: carries q_0
  EXPECT_EQ(a.receive(1, 1, ok, ok), R::Duplicate);
  EXPECT_EQ(a.receive(1, 0, ok, ok), R::ImpossibleStep);  // going back
  EXPECT_EQ(a.step(), 0);
  EXPECT_THROW(a.advance(), InvalidInput);
  EXPECT_THROW(LockstepAgent(s, 6), InvalidInput);
}

TEST(Lockstep, UnboundedScenarioNeverFinishes) {
  Scenario s = loadScenario(test::configPath("free_particle"));
  s.steps = 0;
  LockstepAgent a(s, 0);  // no neighbours: always ready
  for (int k = 0; k < 1000; ++k) {
    ASSERT_FALSE(a.finished());
    a.advance();
  }
  EXPECT_EQ(a.step(), 1000);
}

TEST(Monitor, MetricsFromAgentStatesMatchTheCentralisedIntegrator) {
  const Scenario s = loadScenario(test::configPath("tetrahedron"));
  const Formation f = makeFormation(s);
  FormationMonitor monitor(s);
  VariationalIntegrator vi(f, s.initialPositions, s.initialVelocities, s.timeStep, s.dampingGain,
                           StartMethod::Variational);
  for (long k = 0; k <= s.steps; ++k) {
    if (k > 0) vi.step();
    for (int i = 0; i < s.agentCount(); ++i) {
      const Eigen::VectorXd q = vi.positions().col(i), qp = vi.previousPositions().col(i);
      ASSERT_EQ(monitor.add(i, k, {q.data(), q.data() + 3}, {qp.data(), qp.data() + 3}, s.steps),
                FormationMonitor::Receipt::Accepted);
    }
    const auto done = monitor.takeCompleted();
    ASSERT_EQ(done.size(), 1u);
    const StepMetrics m = measure(vi);
    EXPECT_EQ(done[0].metrics.energy, m.energy);
    EXPECT_EQ(done[0].metrics.linearMomentum, m.linearMomentum);
    EXPECT_EQ(done[0].metrics.angularMomentum, m.angularMomentum);
    EXPECT_NEAR(done[0].agentEnergy.sum(), m.energy, 1e-12 * (1 + m.energy));
    if (k == s.steps) {
      EXPECT_TRUE(done[0].converged);
      EXPECT_EQ(done[0].convergedStep, 847);  // as measured with simulate (config comment)
    }
  }
  using R = FormationMonitor::Receipt;
  const long all = s.steps + 10;
  EXPECT_EQ(monitor.add(0, 3, {0, 0, 0}, {0, 0, 0}, all), R::Duplicate);  // step already completed
  EXPECT_EQ(monitor.add(7, s.steps, {0, 0, 0}, {0, 0, 0}, all), R::UnknownAgent);
  EXPECT_EQ(monitor.add(0, s.steps + 1, {0, 0, 0}, {0, 0, 0}, all), R::ImpossibleStep);  // past the last step
  EXPECT_EQ(monitor.add(0, s.steps, {0, 0}, {0, 0}, all), R::WrongDimension);
  EXPECT_EQ(monitor.add(0, s.steps, {0, NAN, 0}, {0, 0, 0}, all), R::NonFinite);
}

TEST(Monitor, BuffersNothingPastTheAllowedStepAndNamesTheMissingAgents) {
  const Scenario s = loadScenario(test::configPath("hexagon"));
  FormationMonitor monitor(s);
  using R = FormationMonitor::Receipt;
  const std::vector<double> q{1, 2};
  EXPECT_EQ(monitor.add(0, 5, q, q, 4), R::ImpossibleStep);  // the agents may not be there yet
  EXPECT_EQ(monitor.add(0, 0, q, q, 4), R::Accepted);
  EXPECT_EQ(monitor.add(0, 0, q, q, 4), R::Duplicate);
  EXPECT_EQ(monitor.add(2, 0, q, q, 4), R::Accepted);
  EXPECT_EQ(monitor.missingAt(0), (std::vector<int>{1, 3, 4, 5}));
  EXPECT_EQ(monitor.missingAt(1), (std::vector<int>{0, 1, 2, 3, 4, 5}));
  EXPECT_TRUE(monitor.takeCompleted().empty());
}

}  // namespace
}  // namespace vf
