// Agents of other formations (doc/maths.md §10, "Other formations"): held as last heard, sensed
// within reach with the whole constraint (they do not reciprocate), widened by their last step in
// lockstep and by age x max_speed in timed mode; two one-agent formations sent at each other keep
// r with `avoid` and pass through each other without it; far away, nothing changes bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "variational_formation_core/agents/lockstep_agent.hpp"
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/safety/foreign_agents.hpp"
#include "variational_formation_core/safety/foreign_watch.hpp"
#include "variational_formation_core/safety/timed_safety.hpp"

namespace vf {
namespace {

constexpr double kRadius = 0.3;

// One agent at `x`, heading along x at `vx` [m/s], no damping: without the filter it moves in a
// straight line at constant speed (no edges, so no force).
std::string oneAgent(const std::string& name, double x, double y, double vx) {
  return "name: " + name + "\ndimension: 2\nkappa: 0\ntime_step: 0.01\nsteps: 0\n"
         "agents:\n  - {id: 0, initial_position: [" + std::to_string(x) + ", " + std::to_string(y) +
         "], initial_velocity: [" + std::to_string(vx) + ", 0], desired_position: [0, 0]}\n"
         "edges: []\nsafety: {radius: 0.3, sensing_radius: 1, gamma: 0.5}\n";
}

double distance(const std::vector<double>& a, const std::vector<double>& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1]);
}

struct HeadOn {
  double closest = std::numeric_limits<double>::infinity();
  int foreignBindingSteps = 0;
};

// Team a from the left and team b from the right, 0.1 m apart sideways, 400 lockstep steps; each
// hears the other's state after every step, as its topic would bring it.
HeadOn headOn(bool avoid) {
  LockstepAgent a(parseScenario(oneAgent("a", -2.0, 0.05, 1.0), "a"), 0);
  LockstepAgent b(parseScenario(oneAgent("b", 2.0, -0.05, -1.0), "b"), 0);
  auto heardByA = std::make_shared<ForeignAgents>(2), heardByB = std::make_shared<ForeignAgents>(2);
  if (avoid) {
    a.avoid(heardByA);
    b.avoid(heardByB);
  }
  HeadOn run;
  for (int k = 0; k < 400; ++k) {
    heardByA->hold("/b/formation/agent_0", b.position().data(), b.previousPosition().data(), 0.0);
    heardByB->hold("/a/formation/agent_0", a.position().data(), a.previousPosition().data(), 0.0);
    a.advance();
    b.advance();
    run.closest = std::min(run.closest, distance(a.position(), b.position()));
    if (a.foreignConstraintsActive() > 0 || b.foreignConstraintsActive() > 0) ++run.foreignBindingSteps;
  }
  return run;
}

TEST(ForeignAgents, TwoFormationsSentAtEachOtherKeepRWithAvoidAndPassThroughWithout) {
  const HeadOn without = headOn(false);
  EXPECT_LT(without.closest, 0.11);  // the defect: 0.1 m apart sideways, straight through
  EXPECT_EQ(without.foreignBindingSteps, 0);
  const HeadOn with = headOn(true);
  // Each keeps r + the other's last step from the other's last heard position, and the other
  // moves no further than that in the step (no force, the projection only shortens a step).
  EXPECT_GE(with.closest, kRadius - 1e-12);
  EXPECT_GT(with.foreignBindingSteps, 0);
}

TEST(ForeignAgents, FarAwayTheRunIsUnchangedBitForBit) {
  const Scenario s = parseScenario(oneAgent("a", -2.0, 0.0, 1.0), "a");
  LockstepAgent alone(s, 0), avoiding(s, 0);
  auto foreign = std::make_shared<ForeignAgents>(2);
  const double far[2] = {0.0, 5.0}, farBefore[2] = {0.0, 5.01};
  foreign->hold("/b/formation/agent_0", far, farBefore, 0.0);
  avoiding.avoid(foreign);
  for (int k = 0; k < 400; ++k) {
    alone.advance();
    avoiding.advance();
    ASSERT_EQ(alone.position(), avoiding.position()) << "step " << k + 1;
    ASSERT_EQ(avoiding.foreignConstraintsActive(), 0);
  }
}

TEST(ForeignAgents, TheWholeConstraintForAnAgentThatDoesNotReciprocate) {
  SafetySettings s;
  s.radius = 0.3;
  s.sensingRadius = 1.0;
  s.gamma = 0.4;
  const double q[2] = {0.0, 0.0};
  SensedAgent own, other;
  own.id = 1;
  own.position[0] = 0.5;
  other = own;
  other.id = 2;
  other.reciprocates = false;
  std::vector<HalfSpace> out;
  safetyConstraints(s, 2, q, {own, other}, {}, out);
  ASSERT_EQ(out.size(), 2u);
  const double b = 0.25 - 0.09;  // |z|^2 - r^2
  EXPECT_DOUBLE_EQ(out[0].bound, -0.5 * 0.4 * b);
  EXPECT_DOUBLE_EQ(out[1].bound, -0.4 * b);
  EXPECT_EQ(out[1].normal[0], out[0].normal[0]);
}

TEST(ForeignAgents, HoldsTheNewestAndSensesWithinReachAfterTheFormationsOwnIds) {
  ForeignAgents f(2);
  const double p[2] = {1.0, 0.0}, pBefore[2] = {0.9, 0.0}, nan2[2] = {std::nan(""), 0.0};
  EXPECT_TRUE(f.hold("/b/formation/agent_0", p, pBefore, 1.0));
  EXPECT_FALSE(f.hold("/b/formation/agent_1", nan2, p, 1.0));
  const double far[2] = {9.0, 0.0};
  EXPECT_TRUE(f.hold("/c/formation/agent_0", far, far, 1.0));
  EXPECT_EQ(f.size(), 2u);
  const double q[2] = {0.0, 0.0};
  std::vector<SensedAgent> out;
  f.sense(q, 1.0, 0.0, ForeignMargin::LastStep, 0.0, 6, out);  // reach 1 + 0.1 (its last step)
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, 6);
  EXPECT_FALSE(out[0].reciprocates);
  EXPECT_NEAR(out[0].margin, 0.1, 1e-15);
  EXPECT_EQ(f.name(out[0].id - 6), "/b/formation/agent_0");
  out.clear();
  f.sense(q, 1.0, 3.0, ForeignMargin::Age, 0.5, 6, out);  // heard 2 s ago at up to 0.5 m/s: 1 m
  ASSERT_EQ(out.size(), 1u);
  EXPECT_DOUBLE_EQ(out[0].margin, 1.0);
  // A newer state replaces the held one, whatever its step.
  const double moved[2] = {0.0, 3.0};
  EXPECT_TRUE(f.hold("/b/formation/agent_0", moved, moved, 2.0));
  out.clear();
  f.sense(q, 1.0, 0.0, ForeignMargin::LastStep, 0.0, 6, out);
  EXPECT_TRUE(out.empty());
  Positions own(2, 2);
  own << 0.0, 8.5, 0.0, 0.0;
  const ClosestForeign c = f.closest(own);
  EXPECT_DOUBLE_EQ(c.distance, 0.5);
  EXPECT_EQ(c.agent, 1);
  EXPECT_EQ(c.foreign, "/c/formation/agent_0");
  EXPECT_TRUE(std::isinf(ForeignAgents(2).closest(own).distance));
}

TEST(ForeignAgents, TimedModeWidensByAgeTimesMaxSpeed) {
  Scenario s = parseScenario(oneAgent("a", 0.0, 0.0, 0.0), "a");
  TimedSafety safety(s, 0, 0.5, 0.0);
  auto foreign = std::make_shared<ForeignAgents>(2);
  const double p[2] = {1.0, 0.0};
  foreign->hold("/b/formation/agent_0", p, p, 10.0);
  safety.avoid(foreign);
  const double q[2] = {0.0, 0.0};
  double next[2] = {0.004, 0.0};  // max_speed 0.5 x h 0.01 = 0.005 per step
  // Heard 1.5 s ago: it may be 0.75 m nearer, so 1 m is less than r = 0.3 plus 0.75: no step nearer.
  safety.filter(11.5, q, next);
  EXPECT_NEAR(next[0], 0.0, 1e-15);
  EXPECT_EQ(safety.foreignConstraintsActive(), 1);
  next[0] = 0.004;
  safety.filter(10.2, q, next);  // 0.1 m: r + 0.1 = 0.4 < 1 m, and the step does not bind
  EXPECT_EQ(next[0], 0.004);
  EXPECT_EQ(safety.foreignConstraintsActive(), 0);
}

TEST(ForeignWatch, CountsBoundStepsOnceEachAndKeepsTheClosestPairOfTheRun) {
  auto agents = std::make_shared<ForeignAgents>(2);
  ForeignWatch watch(agents);
  EXPECT_EQ(watch.resultLines(), "closest_foreign_approach: ~\nforeign_constraint_steps: 0\n");
  EXPECT_FALSE(watch.note(3, 0));
  EXPECT_TRUE(watch.note(4, 1));   // the first: the monitor says so once
  EXPECT_FALSE(watch.note(4, 2));  // another agent at the same step
  EXPECT_FALSE(watch.note(6, 1));
  EXPECT_EQ(watch.constraintSteps(), 2);
  Positions q(2, 2);
  q << 0.0, 1.0, 0.0, 0.0;
  EXPECT_TRUE(std::isinf(watch.observe(1, q).distance));  // nobody heard yet
  const double p[2] = {1.0, 0.75};
  agents->hold("/team_b/formation/agent_2", p, p, 0.0);
  EXPECT_DOUBLE_EQ(watch.observe(2, q).distance, 0.75);
  q(1, 1) = 0.25;
  EXPECT_DOUBLE_EQ(watch.observe(3, q).distance, 0.5);
  q(1, 1) = 0.0;
  EXPECT_DOUBLE_EQ(watch.observe(4, q).distance, 0.75);  // the status: now; the run: its closest
  EXPECT_DOUBLE_EQ(watch.closestApproach().distance, 0.5);
  EXPECT_EQ(watch.closestApproachStep(), 3);
  EXPECT_EQ(watch.resultLines(),
            "closest_foreign_approach: {distance: 0.5, agents: [agent_1, /team_b/formation/agent_2], step: 3}\n"
            "foreign_constraint_steps: 2\n");
  EXPECT_THROW(ForeignWatch(nullptr), InvalidInput);
}

}  // namespace
}  // namespace vf
