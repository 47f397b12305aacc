// The shape error over all pairs, mirror images, and the endings of a run (desired shape, mirror
// image, folded, still settling, not converged: issue 50), on the shipped hexagon folded by hand
// and on centralised runs.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "test_support.hpp"
#include "variational_formation_core/agents/formation_monitor.hpp"
#include "variational_formation_core/agents/run_verdict.hpp"
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

TEST(ShapeOutcome, TellsTheFiveEndingsApartAndSaysConvergedOnlyForTheDesiredShape) {
  const Scenario s = loadScenario(test::configPath("hexagon"));
  const Formation f = makeFormation(s);
  const Velocities still = Velocities::Zero(2, 6);
  const auto outcome = [&](const Positions& q, const Velocities& v, bool mirrorAllowed) {
    const bool congruent = f.isCongruent(q, v);
    return shapeOutcome(findShape(f, q, v, 1.0, congruent, 0.01, 0.1), congruent ? 40 : -1, mirrorAllowed, 0.014);
  };
  const ShapeOutcome right = outcome(s.desiredPositions, still, false);
  EXPECT_EQ(right.verdict, ShapeVerdict::DesiredShape);
  EXPECT_EQ(right.convergedStep, 40);
  EXPECT_EQ(right.line, "converged to the desired shape at step 40 (t = 0.560 s)");
  EXPECT_EQ(verdictName(right), "desired_shape");
  const ShapeOutcome folded = outcome(foldedHexagon(s.desiredPositions), still, false);
  EXPECT_EQ(folded.verdict, ShapeVerdict::Folded);
  EXPECT_EQ(folded.convergedStep, -1);
  EXPECT_EQ(folded.line, "not converged: folded, at rest with every edge within tolerance but not every pair (shape error 3 m)");
  EXPECT_EQ(verdictName(folded), "folded");
  Positions mirrored = s.desiredPositions;
  mirrored.row(1) *= -1.0;
  const ShapeOutcome mirror = outcome(mirrored, still, false);
  EXPECT_EQ(mirror.verdict, ShapeVerdict::MirrorImage);
  EXPECT_TRUE(mirror.findings.mirrored);
  EXPECT_EQ(mirror.convergedStep, -1);  // congruent from step 40, but not converged
  EXPECT_EQ(mirror.line, "not converged: the mirror image of the desired shape from step 40 (t = 0.560 s; mirror: forbidden)");
  EXPECT_EQ(verdictName(mirror), "mirror_image");
  const ShapeOutcome allowed = outcome(mirrored, still, true);
  EXPECT_EQ(allowed.verdict, ShapeVerdict::DesiredShape);
  EXPECT_EQ(allowed.line, "converged to the desired shape at step 40 (t = 0.560 s), its mirror image (mirror: allowed)");
  // Every edge right but still moving: still settling, not folded, whether the shape is the folded
  // one, the desired one (an agent faster than the congruence's 0.1 m/s), or anything between.
  // The rest speed is a hundredth of the congruence's limit: 0.001 m/s.
  EXPECT_EQ(restSpeed(0.1), 0.001);
  Velocities creeping = still;
  creeping(1, 1) = 0.0011;
  const ShapeOutcome settling = outcome(foldedHexagon(s.desiredPositions), creeping, false);
  EXPECT_EQ(settling.verdict, ShapeVerdict::StillSettling);
  EXPECT_EQ(settling.line, "not converged: still settling at the last step (every edge within tolerance; shape error 3 m; "
                           "fastest agent 0.0011 m/s)");
  EXPECT_EQ(verdictName(settling), "still_settling");
  creeping(1, 1) = 0.0009;
  EXPECT_EQ(outcome(foldedHexagon(s.desiredPositions), creeping, false).verdict, ShapeVerdict::Folded);
  // Slow, but a distance error still falling: agent 1 leaves the centre towards its place at
  // 0.0009 m/s along the line from agent 4, so pair 1-4 (3 m of 6) closes at 0.0009 m/s and
  // would be within 1 % (2.94 m to go) in 3267 s: still settling over a longer horizon (the
  // run's own duration), folded over a shorter one.
  Velocities closing = still;
  closing.col(1) = 0.0009 * (s.desiredPositions.col(1) - s.desiredPositions.col(4)).normalized();
  const auto over = [&](double horizon) {
    return shapeOutcome(findShape(f, foldedHexagon(s.desiredPositions), closing, 1.0, false, 0.01, 0.1, true, nullptr,
                                  horizon), -1, false, 0.014).verdict;
  };
  EXPECT_EQ(over(3300.0), ShapeVerdict::StillSettling);
  EXPECT_EQ(over(3200.0), ShapeVerdict::Folded);
  EXPECT_EQ(over(0.0), ShapeVerdict::Folded);  // speeds alone
  Velocities moving = still;
  moving(0, 3) = 0.5;
  EXPECT_EQ(outcome(s.desiredPositions, moving, false).verdict, ShapeVerdict::StillSettling);
  // A stretched shape, at rest or not: some edge is off.
  const ShapeOutcome stretched = outcome(1.1 * s.desiredPositions, still, false);
  EXPECT_EQ(stretched.verdict, ShapeVerdict::NotConverged);
  EXPECT_EQ(stretched.line, "not converged (final max distance error 0.6 m)");  // the diameter 0-3, 6 m
  EXPECT_EQ(verdictName(stretched), "not_converged");
  EXPECT_EQ(outcome(1.1 * s.desiredPositions, moving, false).verdict, ShapeVerdict::NotConverged);
  const ShapeOutcome blocked = blockedShapeOutcome(right, "blocked: agents 2, 4");
  EXPECT_EQ(blocked.line, "not converged (blocked: agents 2, 4)");
  EXPECT_EQ(verdictName(blocked), "blocked");
  // "converged" begins a line only for the desired shape.
  for (const ShapeOutcome* o : {&folded, &mirror, &settling, &stretched, &blocked}) {
    EXPECT_EQ(o->line.rfind("not converged", 0), 0u) << o->line;
  }
}

TEST(RunVerdict, OnlyTheDesiredShapeMeetsRequireConvergenceAndEachFailureSaysWhy) {
  const Scenario s = loadScenario(test::configPath("hexagon"));
  Scenario required = s;
  required.requireConvergence = true;
  const Formation f = makeFormation(s);
  Positions mirrored = s.desiredPositions;
  mirrored.row(1) *= -1.0;
  Velocities creeping = Velocities::Zero(2, 6);
  creeping(0, 2) = 0.02;
  const auto outcome = [&](const Positions& q, const Velocities& v) {
    const bool congruent = f.isCongruent(q, v);
    return shapeOutcome(findShape(f, q, v, 1.0, congruent, 0.01, 0.1), congruent ? 7 : -1, false, s.timeStep);
  };
  const Velocities still = Velocities::Zero(2, 6);
  EXPECT_TRUE(finishedRunVerdict(required, outcome(s.desiredPositions, still)).succeeded);
  const std::vector<std::pair<ShapeOutcome, std::string>> failures = {
      {outcome(mirrored, still), "its mirror image"},
      {outcome(foldedHexagon(s.desiredPositions), still), "folded"},
      {outcome(foldedHexagon(s.desiredPositions), creeping), "still settling at the last step"},
      {outcome(1.1 * s.desiredPositions, still), "final max distance error 0.6 m"},
      {blockedShapeOutcome(outcome(s.desiredPositions, still), "blocked: agents 2, 4"), "blocked: agents 2, 4"}};
  for (const auto& [o, why] : failures) {
    // Without require_convergence the run succeeds (it ran every step); its line says the shape.
    EXPECT_TRUE(finishedRunVerdict(s, o).succeeded) << o.line;
    const RunVerdict v = finishedRunVerdict(required, o);
    EXPECT_FALSE(v.succeeded) << o.line;
    EXPECT_EQ(v.reason, "the formation did not converge (" + why + "), and the scenario requires it (require_convergence: true)");
  }
}

// Issue 50, defect 5: the hexagon for robots parked near it (test/ros/verdict_settling.yaml, as
// assign_slots writes it) is still moving at its step 300 with every edge within 1 % and a pair
// 1.2 % off; it converges at step 332. And robots parked elsewhere fold it for good.
TEST(ShapeTracker, AShortRunThatStillMovesIsStillSettlingAndALongFoldIsFolded) {
  const auto run = [](const Scenario& s) {
    const Formation f = makeFormation(s);
    ShapeTracker tracker(f, s.mirrorAllowed);
    runScenario(s, Method::Variational, StartMethod::Variational, [&](const Integrator& integ) {
      tracker.observe(integ.stepIndex(), integ.positions(), integ.velocities(), 1.0);
    });
    return tracker.outcome(s.timeStep);
  };
  Scenario s = loadScenario(std::string(VF_SOURCE_DIR) + "/test/ros/verdict_settling.yaml");
  const ShapeOutcome settling = run(s);
  EXPECT_EQ(settling.verdict, ShapeVerdict::StillSettling) << settling.line;
  EXPECT_GT(settling.findings.fastestSpeed, 10.0 * restSpeed(0.1));  // measured 0.026 m/s
  EXPECT_GT(settling.findings.shapeError, 0.01 * 3.0);                // a pair out of 1 % (of 6 m)
  EXPECT_EQ(settling.line.rfind("not converged: still settling at the last step (every edge within tolerance; "
                                "shape error 0.0706 m; fastest agent ", 0), 0u)
      << settling.line;
  s.steps = 3000;
  EXPECT_EQ(run(s).line, "converged to the desired shape at step 332 (t = 4.648 s)");
  // Robots parked so that agent 1 starts inside the shape (seed of the same study): folded, at
  // rest, after 3000 steps.
  s.initialPositions << 4.184, 1.769, -0.98, -2.02, -1.019, 2.306,  //
      -0.232, 1.172, 3.855, 1.157, -3.361, -3.463;
  const ShapeOutcome folded = run(s);
  EXPECT_EQ(folded.verdict, ShapeVerdict::Folded) << folded.line;
  EXPECT_LT(folded.findings.fastestSpeed, 1e-6);
  EXPECT_NEAR(folded.findings.shapeError, 3.0, 1e-6);
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
