// The safety filter of time-driven agents (doc/robots.md, "Safety"): old positions widen r by
// age x max_speed, unicycles by 2 hand_offset; fresh data gives exactly the exact filter; a
// TimedAgent with safety hears every agent, holds until it has, and never steps into another.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/agents/timed_agent.hpp"
#include "variational_formation_core/safety/timed_safety.hpp"

namespace vf {
namespace {

// A rigid graph (K4 without the edge 0-1) whose desired shape puts agents 0 and 1, who share no
// edge, 0.5 m apart: starting 2 m apart on a line, they head at each other.
const std::string kScenario =
    "name: t\ndimension: 2\nkappa: 2\ntime_step: 0.02\nsteps: 1000\n"
    "agents:\n"
    "  - {id: 0, initial_position: [-1, 0], desired_position: [-0.25, 0]}\n"
    "  - {id: 1, initial_position: [1, 0], desired_position: [0.25, 0]}\n"
    "  - {id: 2, initial_position: [0, 2], desired_position: [0, 0.6]}\n"
    "  - {id: 3, initial_position: [0, -2], desired_position: [0, -0.6]}\n"
    "edges: [[0, 2], [0, 3], [1, 2], [1, 3], [2, 3]]\n"
    "safety: {radius: 0.4, sensing_radius: 1.5, gamma: 0.2, max_speed: 2}\n";

double squaredDistance(const double* a, const double* b) {
  return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]);
}

TEST(TimedSafety, MarginIsAgeTimesMaxSpeed) {
  EXPECT_EQ(stalenessMargin(0.0, 0.5), 0.0);
  EXPECT_DOUBLE_EQ(stalenessMargin(0.3, 0.5), 0.15);
  EXPECT_EQ(stalenessMargin(-0.01, 0.5), 0.0);  // clocks a hair apart: no negative margin
}

TEST(TimedSafety, MaxSpeedIsTheScenariosElseTheRobotsElseRefused) {
  SafetySettings s;
  s.maxSpeed = 0.5;
  EXPECT_EQ(timedSafetySpeed(s, 2.0), 0.5);
  s.maxSpeed = std::numeric_limits<double>::infinity();
  EXPECT_EQ(timedSafetySpeed(s, 2.0), 2.0);
  try {
    timedSafetySpeed(s, std::numeric_limits<double>::quiet_NaN());
    ADD_FAILURE() << "timed mode without max_speed accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("safety.max_speed"), std::string::npos) << e.what();
  }
}

TEST(TimedSafety, FreshDataGivesTheExactFilterBitForBit) {
  const Scenario sc = parseScenario(kScenario, "t.yaml");
  TimedSafety safety(sc, 0, 2.0, 0.0);
  const double q1[2] = {-0.3, 0.05}, q2[2] = {0.5, 2.0};
  ASSERT_TRUE(safety.hold(1, q1, 7.0));
  ASSERT_TRUE(safety.hold(2, q2, 7.0));
  EXPECT_EQ(safety.unheard(), std::vector<int>{3});
  ASSERT_TRUE(safety.hold(3, q2 + 0, 7.5));  // sent later than `now`: age 0
  EXPECT_FALSE(safety.hold(2, q1, 6.0));  // older than the held one
  EXPECT_FALSE(safety.hold(0, q1, 8.0));  // its own
  EXPECT_TRUE(safety.unheard().empty());
  const double q[2] = {-0.7, 0.0};
  double next[2] = {-0.62, 0.01}, expected[2] = {-0.62, 0.01};
  const SafeStep& step = safety.filter(7.0, q, next);  // age 0
  std::vector<SensedAgent> sensed(3);
  sensed[0].id = 1;
  sensed[0].position[0] = q1[0];
  sensed[0].position[1] = q1[1];
  sensed[1].id = 2;
  sensed[1].position[0] = q2[0];
  sensed[1].position[1] = q2[1];
  sensed[2] = sensed[1];
  sensed[2].id = 3;
  SafetySettings exact = *sc.safety;
  exact.maxSpeed = 2.0;
  filterNextPosition(exact, sc.timeStep, 2, q, expected, sensed, sc.obstacles);
  ASSERT_TRUE(step.projection.changed);  // 0.32 m from agent 1 after the step: it binds
  EXPECT_EQ(next[0], expected[0]);
  EXPECT_EQ(next[1], expected[1]);
  EXPECT_GE(safety.constraintsActive(), 1);
}

// The rule on random configurations: against the held position c_j, sent `age` ago, the step keeps
// the widened barrier b' = |q - c_j|^2 - (r + 2l + age v)^2 to (1 - γ/2) of itself, and never
// approaches c_j while b' < 0 (2 z·δ >= 0). No step longer than v h.
TEST(TimedSafety, OldPositionsWidenTheRadiusByAgeTimesMaxSpeed) {
  const Scenario sc = parseScenario(kScenario, "t.yaml");
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(-1.0, 1.0), age(0.0, 0.5);
  const double v = 2.0, h = sc.timeStep, gamma = sc.safety->gamma;
  int bound = 0, inside = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const double l = trial % 2 ? 0.1 : 0.0;  // unicycle hand offset, or holonomic
    TimedSafety safety(sc, 0, v, l);
    const double cj[2] = {u(rng), u(rng)}, far[2] = {50.0, 50.0};
    const double a = age(rng);
    safety.hold(1, cj, 10.0 - a);
    safety.hold(2, far, 10.0);
    safety.hold(3, far, 10.0);
    const double q[2] = {u(rng), u(rng)};
    double next[2] = {q[0] + 0.05 * u(rng), q[1] + 0.05 * u(rng)};
    const SafeStep& step = safety.filter(10.0, q, next);
    const double widened = sc.safety->radius + 2.0 * l + a * v;
    const double before = squaredDistance(q, cj) - widened * widened;
    const double after = squaredDistance(next, cj) - widened * widened;
    const double d0 = next[0] - q[0], d1 = next[1] - q[1];
    EXPECT_LE(std::hypot(d0, d1), v * h * (1.0 + 1e-12));
    if (std::sqrt(squaredDistance(q, cj)) >= sc.safety->sensingRadius + 2.0 * l + a * v) continue;
    bound += step.projection.changed;
    if (before >= 0.0) {
      EXPECT_GE(after, (1.0 - 0.5 * gamma) * before - 1e-12) << "trial " << trial;
    } else {
      ++inside;
      const double approach = 2.0 * ((q[0] - cj[0]) * d0 + (q[1] - cj[1]) * d1);
      EXPECT_GE(approach, -1e-12) << "trial " << trial;
    }
  }
  EXPECT_GT(bound, 200);  // the rule was exercised, both outside and inside the widened disc
  EXPECT_GT(inside, 200);
}

TEST(TimedSafety, TheUnicyclesObstacleClearanceGrowsByTheHandOffset) {
  const Scenario sc =
      parseScenario(kScenario + "obstacles:\n  - {center: [0, -1], radius: 0.2}\n", "t.yaml");
  TimedSafety safety(sc, 2, 2.0, 0.1);
  const double far[2] = {40.0, 40.0};
  for (int j : {0, 1, 3}) safety.hold(j, far, 0.0);
  EXPECT_DOUBLE_EQ(safety.settings().radius, 0.6);
  // Hand point 0.2 + r/2 + l = 0.5 m from the disc's centre, stepping straight at it: held.
  const double q[2] = {0.0, -0.5};
  double next[2] = {0.0, -0.52};
  safety.filter(0.0, q, next);
  EXPECT_GE(std::hypot(next[0], next[1] + 1.0), 0.5 - 1e-12);
}

TEST(TimedSafety, AgentHearsNonNeighboursHoldsUntilEveryoneIsHeardAndKeepsApart) {
  const Scenario sc = parseScenario(kScenario, "t.yaml");
  std::vector<TimedAgent> agents;
  for (int i = 0; i < 4; ++i) {
    agents.emplace_back(sc, i, 0.5);
    agents.back().enableSafety(sc, 2.0, 0.0);
  }
  EXPECT_EQ(agents[0].receive(1, 0, {1.0, 0.0}, {1.0, 0.0}, 0.0), TimedAgent::Receipt::Accepted);  // not a neighbour
  const TimedAgent::TickResult held = agents[0].tick(0.0);
  ASSERT_TRUE(held.holding);  // agents 2 and 3 never heard
  ASSERT_EQ(held.stale.size(), 2u);
  EXPECT_EQ(held.stale[0].id, 2);
  // The agents tick in turn on delayed data: each sees the others' states of `lag` ticks ago.
  const int lag = 3;
  std::vector<std::vector<std::vector<double>>> sent(4);  // per agent, its state after each tick
  for (int i = 0; i < 4; ++i) sent[i].push_back(agents[i].position());
  double closest = 1e9;
  long active = 0;
  for (int k = 1; k <= 1000; ++k) {
    const double now = k * sc.timeStep;
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) {
        if (j == i) continue;
        const int m = std::max(0, static_cast<int>(sent[j].size()) - 1 - lag);
        agents[i].receive(j, m, sent[j][m], sent[j][m], now, m * sc.timeStep);
      }
    }
    for (int i = 0; i < 4; ++i) {
      agents[i].tick(now);
      active += agents[i].constraintsActive();
    }
    for (int i = 0; i < 4; ++i) sent[i].push_back(agents[i].position());
    closest = std::min(closest, std::sqrt(squaredDistance(agents[0].position().data(), agents[1].position().data())));
    if (k % 250 == 0) std::printf("t = %.0f s: agents 0 and 1 %.4f m apart\n", now, std::sqrt(squaredDistance(agents[0].position().data(), agents[1].position().data())));
  }
  // The filter bound: 0 and 1 want to be 0.5 m apart, below r + 4 ticks x 2 m/s = 0.56 m
  // (3 ticks of lag, and the tick the state was made at).
  EXPECT_GT(active, 0);
  EXPECT_GE(closest, sc.safety->radius);
  EXPECT_LT(closest, 0.6);  // and they did come near
}

}  // namespace
}  // namespace vf
