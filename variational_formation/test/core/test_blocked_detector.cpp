// Blocked, not silent: the detector's rule on made-up sequences, and a formation the filter
// holds for ever (three agents on a line, one of which must pass another), run centrally.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "variational_formation_core/agents/blocked_detector.hpp"
#include "variational_formation_core/agents/run_tracker.hpp"
#include "variational_formation_core/agents/run_verdict.hpp"
#include "variational_formation_core/model/shape_outcome.hpp"
#include "variational_formation_core/safety/safety_stage.hpp"
#include "variational_formation_core/integrators/step_metrics.hpp"

namespace vf {
namespace {

const std::vector<int> kPair{2, 4};
const std::vector<int> kNone;

TEST(BlockedDetector, BlockedOnceTheErrorHasNotFallenForTheWindowWhileTheFilterBinds) {
  BlockedDetector detector(1.0, 0.1);  // 10 steps
  EXPECT_FALSE(detector.update(0, 1.0, false, kPair, kNone));
  for (long k = 1; k < 10; ++k) EXPECT_FALSE(detector.update(k, 0.995, false, kPair, kNone)) << k;
  EXPECT_TRUE(detector.update(10, 0.995, false, kPair, kNone));
  EXPECT_TRUE(detector.blocked());
  EXPECT_EQ(detector.description(), "blocked: agents 2, 4");
}

TEST(BlockedDetector, NotBlockedWhileTheErrorFallsOrTheFilterIsIdleOrTheShapeHolds) {
  BlockedDetector falling(1.0, 0.1);
  double error = 1.0;
  for (long k = 0; k < 100; ++k, error *= 0.98) EXPECT_FALSE(falling.update(k, error, false, kPair, kNone));
  BlockedDetector idle(1.0, 0.1);
  for (long k = 0; k < 100; ++k) EXPECT_FALSE(idle.update(k, 1.0, false, kNone, kNone));
  // The error rises after the filter lets go, then stays: blocked 10 steps after its last fall.
  EXPECT_TRUE(idle.update(100, 1.0, false, kPair, std::vector<int>{0}));
  EXPECT_EQ(idle.description(), "blocked: agents 2, 4; obstacles 0");
  BlockedDetector congruent(1.0, 0.1);
  for (long k = 0; k < 100; ++k) EXPECT_FALSE(congruent.update(k, 1e-3, true, kPair, kNone));
}

// test/scenarios/blocked_line.yaml: agent 1 must pass agent 2 on a line, which the filter forbids.
Scenario lineScenario() { return loadScenario(std::string(VF_SOURCE_DIR) + "/test/scenarios/blocked_line.yaml"); }

TEST(RunTracker, EndsABlockedRunNamingTheAgentsThatBlockEachOther) {
  const Scenario s = lineScenario();
  const CommandSchedule none;
  RunTracker tracker(s, none);
  long last = -1;
  double closest = 1e9;
  runCentralised(s, Method::Variational, StartMethod::Variational, nullptr, [&](const Integrator& integrator) {
    last = integrator.stepIndex();
    closest = std::min(closest, measure(integrator).minSeparation);
    return tracker.observe(integrator);
  });
  EXPECT_TRUE(tracker.blocked());
  EXPECT_LT(last, s.steps);  // it stopped instead of running on
  EXPECT_GT(last, 100);      // blocked_after = 2 s = 100 steps at least
  EXPECT_EQ(tracker.blockedBy(), "blocked: agents 1, 2");
  // The run's verdict is the shape's, blocked (simulate's last line).
  const Formation formation = makeFormation(s);
  ShapeTracker shape(formation, s.mirrorAllowed);
  runCentralised(s, Method::Variational, StartMethod::Variational, nullptr, [&](const Integrator& integrator) {
    shape.observe(integrator.stepIndex(), integrator.positions(), integrator.velocities(), 1.0);
    return integrator.stepIndex() < last;
  });
  const ShapeOutcome outcome = blockedShapeOutcome(shape.outcome(s.timeStep), tracker.blockedBy());
  EXPECT_EQ(outcome.verdict, ShapeVerdict::NotConverged);
  EXPECT_EQ(outcome.line, "not converged (blocked: agents 1, 2)");
  EXPECT_GT(outcome.findings.maxEdgeError, 0.5);
  EXPECT_GE(closest, 0.25);
  EXPECT_EQ(tracker.closestApproach().distance, closest);
  EXPECT_EQ(tracker.closestApproach().first, 1);
  EXPECT_EQ(tracker.closestApproach().second, 2);
  EXPECT_GT(tracker.filterActiveSteps(), 50);
  Scenario required = s;
  required.requireConvergence = true;
  EXPECT_EQ(finishedRunVerdict(required, outcome).reason,
            "the formation did not converge (blocked: agents 1, 2), and the scenario requires it "
            "(require_convergence: true)");
}

}  // namespace
}  // namespace vf
