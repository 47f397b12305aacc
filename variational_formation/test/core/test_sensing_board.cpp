// SensingBoard and the lockstep agent with safety on: who senses whom is decided exactly, and
// agents that exchange states in any order (each with a board of its own, or all sharing one, as
// in a manager), killed and resumed, reproduce the centralised run with its SafetyStage bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <sstream>

#include "lockstep_delivery.hpp"
#include "variational_formation_core/agents/lockstep_agent.hpp"
#include "variational_formation_core/safety/safety_stage.hpp"
#include "variational_formation_core/agents/sensing_board.hpp"
#include "variational_formation_core/integrators/step_metrics.hpp"
#include "variational_formation_core/integrators/variational_integrator.hpp"

namespace vf {
namespace {

/// Six agents that start on the hexagon's circle in shuffled places (side 1 m), so that paths
/// cross and the filter binds; r = 0.25 m, R = 1 m.
Scenario crossingHexagon(double maxSpeed, long steps) {
  std::ostringstream y;
  y.precision(17);
  y << "name: crossing\ndimension: 2\nkappa: 2.0\ntime_step: 0.02\nsteps: " << steps << "\nagents:\n";
  const double pi = std::acos(-1.0);
  const int slot[6] = {3, 0, 4, 1, 5, 2};  // a shuffle, not a rotation: paths must cross
  for (int i = 0; i < 6; ++i) {
    const double a = pi / 3 * i, b = pi / 3 * slot[i] + 0.05 * i;
    y << "  - {id: " << i << ", initial_position: [" << 1.1 * std::cos(b) << ", " << 1.1 * std::sin(b)
      << "], initial_velocity: [0, 0], desired_position: [" << std::cos(a) << ", " << std::sin(a) << "]}\n";
  }
  y << "edges: [[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [5, 0], [0, 2], [0, 3], [0, 4]]\n";
  y << "safety: {radius: 0.25, sensing_radius: 1.0, gamma: 0.2";
  if (std::isfinite(maxSpeed)) y << ", max_speed: " << maxSpeed;
  y << "}\nobstacles:\n  - {center: [0.0, 1.6], radius: 0.2}\n";
  return parseScenario(y.str(), "crossing.yaml");
}

/// The centralised run (simulate's: VariationalIntegrator with the scenario's SafetyStage), each
/// step's positions, and how many steps some half-space bound.
std::vector<Positions> centralised(const Scenario& s, long* bindingSteps) {
  const Formation formation = makeFormation(s);  // the integrator keeps a reference
  VariationalIntegrator reference(formation, s.initialPositions, s.initialVelocities, s.timeStep,
                                  s.dampingGain, StartMethod::Variational);
  const auto stage = makeSafetyStage(s);
  reference.attachSafety(stage);
  std::vector<Positions> expected{reference.positions()};
  *bindingSteps = 0;
  for (long k = 0; k < s.steps; ++k) {
    reference.step();
    if (!stage->bindingAgents().empty()) ++*bindingSteps;
    expected.push_back(reference.positions());
  }
  return expected;
}

TEST(SensingBoard, CompleteOnlyWhenEveryAgentsPositionAtTheStepIsHeld) {
  SensingBoard b(3, 2, 1.0);
  const double q0[2] = {0.0, 0.0}, q1[2] = {0.5, 0.0}, q2[2] = {3.0, 0.0}, q3[2] = {0.2, 0.0};
  EXPECT_FALSE(b.complete(0));
  EXPECT_EQ(b.offer(0, 0, q0, q0), SensingBoard::Offer::Accepted);
  EXPECT_EQ(b.offer(1, 0, q1, q1), SensingBoard::Offer::Accepted);
  EXPECT_EQ(b.missing(0, 10), std::vector<int>{2});
  int woken = 0;
  EXPECT_TRUE(b.whenComplete(0, [&] { ++woken; }));
  std::vector<SensedAgent> out;
  EXPECT_FALSE(b.sensed(0, 0, out));
  EXPECT_EQ(b.offer(2, 1, q2, q2), SensingBoard::Offer::Accepted);  // step 1 carries q^0
  EXPECT_EQ(woken, 1);
  EXPECT_TRUE(b.complete(0));
  EXPECT_FALSE(b.complete(1));
  EXPECT_FALSE(b.whenComplete(0, [&] { ++woken; }));
  ASSERT_TRUE(b.sensed(0, 0, out));
  ASSERT_EQ(out.size(), 1u);  // agent 1 at 0.5; agent 2 at 3 is beyond R
  EXPECT_EQ(out[0].id, 1);
  EXPECT_EQ(out[0].position[0], 0.5);
  EXPECT_EQ(b.offer(2, 1, q2, q2), SensingBoard::Offer::Duplicate);
  EXPECT_EQ(b.offer(2, 0, q2, q2), SensingBoard::Offer::GoesBack);
  EXPECT_EQ(b.offer(3, 0, q2, q2), SensingBoard::Offer::UnknownSender);
  const double bad[2] = {std::nan(""), 0.0};
  EXPECT_EQ(b.offer(0, 1, bad, q0), SensingBoard::Offer::NonFinite);
  // Agent 2 two steps on (as no barrier allows): q_2^0 is gone, step 0 is no longer complete.
  EXPECT_EQ(b.offer(2, 2, q3, q2), SensingBoard::Offer::Accepted);
  EXPECT_FALSE(b.complete(0));
  EXPECT_FALSE(b.complete(1));
  EXPECT_EQ(b.missing(1, 10), (std::vector<int>{0, 1}));
}

TEST(SensingBoard, SensedSetsAreSafetyStagesOnRandomConfigurations) {
  // The board's sets, fed the states in a random order, against the grid's within() that
  // SafetyStage uses, on dense random configurations where many pairs sit near R.
  std::mt19937 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 40, d = trial % 2 ? 3 : 2;
    std::uniform_real_distribution<double> u(-2.0, 2.0);
    Positions q(d, n);
    for (int j = 0; j < n; ++j) {
      for (int a = 0; a < d; ++a) q(a, j) = u(rng);
    }
    SensingBoard b(n, d, 1.0);
    std::vector<int> order(static_cast<std::size_t>(n));
    for (int j = 0; j < n; ++j) order[static_cast<std::size_t>(j)] = j;
    std::shuffle(order.begin(), order.end(), rng);
    for (int j : order) {
      // Half of them already one step on: their state at 6 carries q^5 as the previous position.
      const double* col = q.col(j).data();
      if (j % 2) {
        const double ahead[3] = {col[0] + 0.1, col[1], d == 3 ? col[2] : 0.0};
        b.offer(j, 6, ahead, col);
      } else {
        b.offer(j, 5, col, col);
      }
    }
    SpatialGrid grid;
    grid.build(q, 1.0);
    std::vector<SensedAgent> got;
    for (int i = 0; i < n; ++i) {
      std::vector<int> want;
      grid.within(q, i, 1.0, want);
      ASSERT_TRUE(b.sensed(i, 5, got));
      ASSERT_EQ(got.size(), want.size()) << trial << " " << i;
      for (std::size_t k = 0; k < got.size(); ++k) {
        EXPECT_EQ(got[k].id, want[k]);
        for (int a = 0; a < d; ++a) EXPECT_EQ(got[k].position[a], q(a, want[k]));
      }
    }
  }
}

/// Runs the agents through lockstep_delivery's random order; `shared`: one board for all.
void runLockstep(const Scenario& s, bool shared, unsigned seed, const std::vector<Positions>& expected,
                 int* maxActive) {
  const auto board = shared ? std::make_shared<SensingBoard>(s.agentCount(), s.dimension, s.safety->sensingRadius)
                            : nullptr;
  std::vector<LockstepAgent> agents;
  for (int i = 0; i < s.agentCount(); ++i) agents.emplace_back(s, i, StartMethod::Variational, board);
  std::mt19937 rng(seed);
  long checked = 0;
  *maxActive = 0;
  test::runInRandomOrder(agents, expected, rng, "crossing", &checked,
                         [&](LockstepAgent& a) { *maxActive = std::max(*maxActive, a.constraintsActive()); });
  EXPECT_EQ(checked, s.steps * s.agentCount());
}

TEST(LockstepSafety, RandomDeliveryOrderReproducesSafetyStageBitForBit) {
  for (double maxSpeed : {std::numeric_limits<double>::infinity(), 0.8}) {
    const Scenario s = crossingHexagon(maxSpeed, 250);
    long binding = 0;
    const auto expected = centralised(s, &binding);
    EXPECT_GT(binding, 10) << "the filter must bind for this test to mean anything";
    for (unsigned seed = 1; seed <= 6; ++seed) {
      int maxActive = 0;
      runLockstep(s, /*shared=*/seed % 2 == 0, seed, expected, &maxActive);
      EXPECT_GT(maxActive, 0) << "seed " << seed;
    }
  }
}

TEST(LockstepSafety, WithoutSafetyNonNeighboursAreStillRefused) {
  Scenario s = crossingHexagon(std::numeric_limits<double>::infinity(), 10);
  s.safety.reset();
  s.obstacles.clear();
  LockstepAgent a(s, 1);  // neighbours 0, 2
  const std::vector<double> q{0.0, 0.0};
  EXPECT_EQ(a.receive(4, 0, q, q), LockstepAgent::Receipt::UnknownSender);
  EXPECT_EQ(a.board(), nullptr);
  EXPECT_TRUE(a.missingSensed(10).empty());
}

TEST(LockstepSafety, ANonNeighboursStateIsCheckedAndNeededBeforeTheStep) {
  const Scenario s = crossingHexagon(std::numeric_limits<double>::infinity(), 10);
  LockstepAgent a(s, 1);  // neighbours 0, 2; 3, 4, 5 are sensed only
  auto col = [&](int j) {
    return std::vector<double>(s.initialPositions.col(j).data(), s.initialPositions.col(j).data() + 2);
  };
  using R = LockstepAgent::Receipt;
  EXPECT_EQ(a.receive(0, 0, col(0), col(0)), R::Accepted);
  EXPECT_EQ(a.receive(2, 0, col(2), col(2)), R::Accepted);
  EXPECT_FALSE(a.ready());  // the board lacks 3, 4, 5
  EXPECT_EQ(a.missingSensed(10), (std::vector<int>{3, 4, 5}));
  EXPECT_EQ(a.receive(3, 0, {1.0}, {1.0}), R::WrongDimension);
  EXPECT_EQ(a.receive(3, 0, {std::nan(""), 0.0}, col(3)), R::NonFinite);
  EXPECT_EQ(a.receive(3, 2, col(3), col(3)), R::ImpossibleStep);  // two ahead: the barrier forbids it
  EXPECT_EQ(a.receive(3, 0, col(3), col(3)), R::Accepted);
  EXPECT_EQ(a.receive(3, 0, col(3), col(3)), R::Duplicate);
  EXPECT_EQ(a.receive(4, 1, col(4), col(4)), R::Accepted);  // one ahead: carries q^0
  EXPECT_EQ(a.receive(4, 0, col(4), col(4)), R::ImpossibleStep);  // going back
  EXPECT_EQ(a.receive(9, 0, col(4), col(4)), R::UnknownSender);
  EXPECT_FALSE(a.ready());
  EXPECT_EQ(a.receive(5, 0, col(5), col(5)), R::Accepted);
  EXPECT_TRUE(a.ready());
  long step = 0;
  std::vector<double> q, qPrev;
  ASSERT_TRUE(a.neighbourState(4, step, q, qPrev));  // a restarted agent 4 may recover from it
  EXPECT_EQ(step, 1);
}

TEST(LockstepSafety, AgentsKilledAndResumedFromTheNewestHeldStateStayBitForBit) {
  // A kill -9: the agent is replaced by a new one, which resumes from the newest state of it
  // any other agent holds, and is then given every other agent's newest state (the latched
  // topics it subscribes to anew). Kills fall on steps where its constraints bind.
  const Scenario s = crossingHexagon(std::numeric_limits<double>::infinity(), 250);
  long binding = 0;
  const auto expected = centralised(s, &binding);
  for (unsigned seed = 11; seed <= 16; ++seed) {
    std::vector<LockstepAgent> agents;
    for (int i = 0; i < s.agentCount(); ++i) agents.emplace_back(s, i);
    std::mt19937 rng(seed), chance(seed + 100);
    int kills = 0;
    auto onTurn = [&](LockstepAgent& a) {
      if (a.constraintsActive() == 0 || a.finished() || chance() % 20 != 0) return;
      const int id = a.id();
      long best = -1, step = 0;
      std::vector<double> q, qPrev, bestQ, bestPrev;
      for (const auto& o : agents) {
        if (o.id() != id && o.neighbourState(id, step, q, qPrev) && step > best) {
          best = step;
          bestQ = q;
          bestPrev = qPrev;
        }
      }
      a = LockstepAgent(s, id);
      if (best > 0) a.resume(best, bestQ, bestPrev);
      for (const auto& o : agents) {
        if (o.id() != id) a.receive(o.id(), o.step(), o.position(), o.previousPosition());
      }
      ++kills;
    };
    long checked = 0;
    test::runInRandomOrder(agents, expected, rng, "crossing, kills", &checked, onTurn);
    EXPECT_GT(kills, 3) << "seed " << seed;
  }
}

}  // namespace
}  // namespace vf
