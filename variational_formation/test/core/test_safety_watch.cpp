// The monitor's view of the safety filter (SafetyWatch): the closest pair per step against a brute
// force search, constraints_active summed by step (lockstep) or newest per agent (timed), the
// closest approach and filter_active_steps of the run, and the blocked verdict of BlockedDetector.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "variational_formation_core/agents/formation_monitor.hpp"
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/safety/safety_watch.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "test_support.hpp"

namespace vf {
namespace {

const std::string kLine =
    "name: t\ndimension: 2\nkappa: 2\ntime_step: 0.02\nsteps: 3000\n"
    "agents:\n"
    "  - {id: 0, initial_position: [0, 0], desired_position: [0, 0]}\n"
    "  - {id: 1, initial_position: [1, 0], desired_position: [2, 0]}\n"
    "  - {id: 2, initial_position: [2, 0], desired_position: [1, 0]}\n"
    "edges: [[0, 1], [1, 2], [0, 2]]\n"
    "safety: {radius: 0.25, sensing_radius: 1, gamma: 0.2}\n";

double bruteClosest(const Positions& q) {
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < q.cols(); ++i) {
    for (Eigen::Index j = i + 1; j < q.cols(); ++j) best = std::min(best, (q.col(i) - q.col(j)).norm());
  }
  return best;
}

TEST(SafetyWatch, MinSeparationIsTheClosestPairOfEveryStep) {
  // 600 points scattered over 30 m x 30 m (observe measures whatever q it is given): the grid's
  // answer is the brute force one, exactly.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 30.0);
  const int n = 600;
  Positions q(2, n);
  for (int i = 0; i < n; ++i) {
    q(0, i) = u(rng);
    q(1, i) = u(rng);
  }
  const Scenario sc = parseScenario(kLine, "t.yaml");
  SafetyWatch watch(sc, 10.0, false);
  for (int step = 0; step < 5; ++step) {
    for (int i = 0; i < n; ++i) q(0, i) += 0.01 * step;
    watch.observe(step, q, 1.0, false);
    EXPECT_EQ(watch.minSeparation(), bruteClosest(q)) << "step " << step;
  }
}

// A diverging run (issue 50): the monitor measured the agents' last finite step, far out, and its
// closest pair search never ended (the monitor spun and the result file stayed "running"). The
// monitor's path, FormationMonitor's snapshot then SafetyWatch, must end on any finite step.
TEST(SafetyWatch, EndsOnAStepFarOut) {
  const Scenario sc = parseScenario(kLine, "t.yaml");
  const std::vector<std::vector<double>> far = {{-1e300, 0.0}, {1e300, 0.0}, {0.0, 1e300}};
  const auto measureFarOut = [&sc, &far](SafetyWatch& watch) {
    FormationMonitor monitor(sc);
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(monitor.add(i, 0, far[static_cast<std::size_t>(i)], far[static_cast<std::size_t>(i)], 0),
                FormationMonitor::Receipt::Accepted);
    }
    const std::vector<FormationSnapshot> done = monitor.takeCompleted();
    EXPECT_EQ(done.size(), 1u);
    for (const FormationSnapshot& s : done) watch.observe(0, s.positions, s.metrics.maxDistanceError, s.converged);
  };
  test::expectEndsWithin(10, [&] {
    SafetyWatch watch(sc, 10.0, false);
    measureFarOut(watch);
  });
  if (HasFailure()) return;
  SafetyWatch watch(sc, 10.0, false);
  measureFarOut(watch);
  // No pair is near enough for its squared distance to be a double: none is named.
  EXPECT_EQ(watch.minSeparation(), std::numeric_limits<double>::infinity());
  EXPECT_EQ(watch.resultLines(), "closest_approach: ~\nfilter_active_steps: 0\n");
}

TEST(SafetyWatch, LockstepSumsTheStepsValuesAndFindsTheBlock) {
  const Scenario sc = parseScenario(kLine, "t.yaml");
  SafetyWatch watch(sc, 2.0, false);  // 2 s = 100 steps
  Positions q(2, 3);
  q << 0.0, 1.0, 1.25, 0.0, 0.0, 0.0;
  // Agents 1 and 2 press against each other from step 1 on; states of later steps arrive early.
  for (long k = 0; k <= 200; ++k) {
    for (int i = 0; i < 3; ++i) watch.note(i, k + 3, i > 0 ? 1 : 0);  // 3 steps ahead of the measure
    if (k == 0) {
      for (int i = 0; i < 3; ++i) watch.note(i, 0, 0);
      for (int i = 0; i < 3; ++i) watch.note(i, 1, 0);
      for (int i = 0; i < 3; ++i) watch.note(i, 2, 0);
    }
    const bool blocked = watch.observe(k, q, 0.75, false);
    EXPECT_EQ(watch.constraintsActive(), k >= 3 ? 2 : 0) << "step " << k;
    EXPECT_DOUBLE_EQ(watch.minSeparation(), 0.25);
    if (blocked) {
      // The error last fell at step 0 (the first measure): blocked 100 steps later, while binding.
      EXPECT_EQ(k, 100);
      break;
    }
  }
  ASSERT_TRUE(watch.blocked());
  EXPECT_EQ(watch.description(), "blocked: agents 1, 2");
  EXPECT_EQ(watch.filterActiveSteps(), 98);  // steps 3..100
  EXPECT_EQ(watch.closestApproach().first, 1);
  EXPECT_EQ(watch.closestApproach().second, 2);
  EXPECT_EQ(watch.resultLines(), "closest_approach: {distance: 0.25, agents: [1, 2], step: 0}\nfilter_active_steps: 98\n");
}

TEST(SafetyWatch, ProgressOrShapeIsNotBlocked) {
  const Scenario sc = parseScenario(kLine, "t.yaml");
  SafetyWatch falling(sc, 2.0, false), inShape(sc, 2.0, false);
  Positions q(2, 3);
  q << 0.0, 1.0, 1.5, 0.0, 0.0, 0.0;
  double error = 1.0;
  for (long k = 0; k <= 400; ++k) {
    for (int i = 0; i < 3; ++i) {
      falling.note(i, k, 1);
      inShape.note(i, k, 1);
    }
    error *= 0.999;  // 1% every ~10 steps: progress
    EXPECT_FALSE(falling.observe(k, q, error, false)) << k;
    EXPECT_FALSE(inShape.observe(k, q, 1.0, true)) << k;
  }
  EXPECT_EQ(falling.filterActiveSteps(), 401);
}

TEST(SafetyWatch, TimedTakesEachAgentsNewestValue) {
  const Scenario sc = parseScenario(kLine, "t.yaml");
  SafetyWatch watch(sc, 2.0, true);
  Positions q(2, 3);
  q << 0.0, 1.0, 2.0, 0.0, 0.0, 0.0;
  watch.note(1, 10, 2);
  watch.note(2, 12, 1);
  watch.note(2, 11, 5);  // older than the held one
  watch.observe(0, q, 1.0, false);
  EXPECT_EQ(watch.constraintsActive(), 3);
  EXPECT_DOUBLE_EQ(watch.minSeparation(), 1.0);
  watch.note(1, 13, 0);
  watch.observe(1, q, 1.0, false);
  EXPECT_EQ(watch.constraintsActive(), 1);
  EXPECT_EQ(watch.filterActiveSteps(), 2);
  EXPECT_THROW(SafetyWatch(sc, 0.0, true), InvalidInput);
}

}  // namespace
}  // namespace vf
