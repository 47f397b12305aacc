// The shape error over all pairs, mirror images, and the three endings of a run, on the
// shipped hexagon folded by hand and on its centralised run.
#include <gtest/gtest.h>

#include <cmath>

#include "test_support.hpp"
#include "variational_formation_core/agents/formation_monitor.hpp"
#include "variational_formation_core/model/shape_outcome.hpp"
#include "variational_formation_core/integrators/step_metrics.hpp"

namespace vf {
namespace {

// The shipped hexagon (side 3, centre at the origin) has 9 edges; agent 1 is linked only to 0
// and 2. Reflected through the chord 0-2 it lands on the centre: every edge keeps its length,
// and the pair 1-4 shrinks from 6 (opposite corners) to 3.
Positions foldedHexagon(const Positions& desired) {
  Positions q = desired;
  q.col(1) << 0.0, 0.0;
  return q;
}

TEST(ShapeError, SeesAFoldWhereEdgeErrorsDoNot) {
  const Scenario s = loadScenario(test::configPath("hexagon"));
  const Formation f = makeFormation(s);
  const Positions folded = foldedHexagon(s.desiredPositions);
  EXPECT_LT(f.maxDistanceError(folded), 1e-12);
  EXPECT_NEAR(f.shapeError(folded), 3.0, 1e-12);
  EXPECT_NEAR(f.shapeError(folded, 2.0), 9.0, 1e-12);  // against s = 2, pair 1-4: |3 - 2 * 6|
  EXPECT_EQ(f.shapeError(s.desiredPositions), 0.0);
  // A rotated, translated copy has no shape error; a mirror image has none either.
  Positions mirrored = s.desiredPositions;
  mirrored.row(0) *= -1.0;
  EXPECT_LT(f.shapeError(mirrored), 1e-12);
  Positions broken = s.desiredPositions;
  broken(0, 2) = std::nan("");
  EXPECT_TRUE(std::isnan(f.shapeError(broken)));
}

TEST(ShapeOutcome, TellsTheThreeEndingsApart) {
  const Scenario s = loadScenario(test::configPath("hexagon"));
  const Formation f = makeFormation(s);
  const Velocities still = Velocities::Zero(2, 6);
  const auto outcome = [&](const Positions& q, const Velocities& v, bool mirrorAllowed) {
    const bool congruent = f.isCongruent(q, v);
    return shapeOutcome(findShape(f, q, v, 1.0, congruent, 0.01, 0.1), congruent ? 40 : -1, mirrorAllowed, 0.014);
  };
  const ShapeOutcome right = outcome(s.desiredPositions, still, false);
  EXPECT_EQ(right.verdict, ShapeVerdict::DesiredShape);
  EXPECT_EQ(right.line, "converged to the desired shape at step 40 (t = 0.560 s)");
  const ShapeOutcome folded = outcome(foldedHexagon(s.desiredPositions), still, false);
  EXPECT_EQ(folded.verdict, ShapeVerdict::OtherShape);
  EXPECT_EQ(folded.line, "edges converged but the shape is not the desired one (shape error 3 m)");
  Positions mirrored = s.desiredPositions;
  mirrored.row(1) *= -1.0;
  const ShapeOutcome mirror = outcome(mirrored, still, false);
  EXPECT_EQ(mirror.verdict, ShapeVerdict::OtherShape);
  EXPECT_TRUE(mirror.findings.mirrored);
  EXPECT_EQ(mirror.line.rfind("edges converged but the shape is not the desired one (its mirror image; shape error ", 0), 0u)
      << mirror.line;
  const ShapeOutcome allowed = outcome(mirrored, still, true);
  EXPECT_EQ(allowed.verdict, ShapeVerdict::DesiredShape);
  EXPECT_EQ(allowed.line, "converged to the desired shape at step 40 (t = 0.560 s), its mirror image (mirror: allowed)");
  // Right shape, but moving: not converged; and a stretched shape.
  Velocities moving = still;
  moving(0, 3) = 0.5;
  EXPECT_EQ(outcome(s.desiredPositions, moving, false).verdict, ShapeVerdict::NotConverged);
  const ShapeOutcome stretched = outcome(1.1 * s.desiredPositions, still, false);
  EXPECT_EQ(stretched.verdict, ShapeVerdict::NotConverged);
  EXPECT_EQ(stretched.line, "not converged (final max distance error 0.6 m)");  // the diameter 0-3, 6 m
}

TEST(ShapeTracker, AgreesWithTheMonitorOnTheShippedHexagon) {
  // The hexagon's file says it is congruent from step 210 (measured by the monitor's test).
  const Scenario s = loadScenario(test::configPath("hexagon"));
  const Formation f = makeFormation(s);
  ShapeTracker tracker(f, s.mirrorAllowed);
  FormationMonitor monitor(s);
  Positions previous = s.initialPositions;
  runScenario(s, Method::Variational, StartMethod::Variational, [&](const Integrator& integ) {
    tracker.observe(integ.stepIndex(), integ.positions(), integ.velocities(), 1.0);
    std::vector<double> q(2), p(2);
    for (int i = 0; i < 6; ++i) {
      for (int a = 0; a < 2; ++a) {
        q[a] = integ.positions()(a, i);
        p[a] = previous(a, i);
      }
      monitor.add(i, integ.stepIndex(), q, p, s.steps);
    }
    previous = integ.positions();
    for (const FormationSnapshot& snap : monitor.takeCompleted()) {
      EXPECT_EQ(snap.shape.shapeError, f.shapeError(integ.positions()));
      EXPECT_EQ(snap.shape.mirrored, false);
    }
  });
  const ShapeOutcome o = tracker.outcome(s.timeStep);
  EXPECT_EQ(o.line, "converged to the desired shape at step 210 (t = 2.940 s)");
  EXPECT_LT(o.findings.shapeError, 0.01 * 3.0);
}

TEST(ShapeOutcome, TheAllPairsErrorCostsAtMostFiftyAgentsPerStep) {
  for (long k = 0; k < 50; ++k) EXPECT_TRUE(shapeErrorMeasuredAt(k, 50, 0));
  // 250 agents: (250/50)^2 = 25 times the pairs, measured every 25th step and at the last.
  int measured = 0;
  for (long k = 0; k <= 1000; ++k) measured += shapeErrorMeasuredAt(k, 250, 990) ? 1 : 0;
  EXPECT_EQ(measured, 41 + 1);  // 0, 25, ..., 1000, and 990
  EXPECT_TRUE(shapeErrorMeasuredAt(990, 250, 990));
  EXPECT_FALSE(shapeErrorMeasuredAt(991, 250, 990));
  EXPECT_TRUE(shapeErrorMeasuredAt(50, 51, 0));  // ceil(1.02^2) = 2
  EXPECT_FALSE(shapeErrorMeasuredAt(51, 51, 0));
  // 200 agents: 16 times the pairs of 50, every 16th step.
  EXPECT_TRUE(shapeErrorMeasuredAt(32, 200, 0));
  EXPECT_FALSE(shapeErrorMeasuredAt(33, 200, 0));
}

}  // namespace
}  // namespace vf
