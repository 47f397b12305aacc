// FormationMonitor under commands (doc/maths.md §8-9): a commanded run is measured as simulate
// measures it (distances against s d_ij, energy with V_s, bit for bit), it becomes congruent while
// it travels, turns and holds the scaled shape, and a formation that does not move as commanded
// is not congruent. Without a command nothing changes (test_lockstep, test_protocol).
#include <gtest/gtest.h>

#include <cmath>
#include <utility>
#include <vector>

#include "test_support.hpp"
#include "variational_formation_core/agents/formation_monitor.hpp"
#include "variational_formation_core/integrators/step_metrics.hpp"
#include "variational_formation_core/model/shape_outcome.hpp"

namespace vf {
namespace {

/// Offers every agent's (q_k, q_{k-1}) and returns the completed snapshot of step k.
FormationSnapshot measureAt(FormationMonitor& monitor, long k, const Positions& q, const Positions& qPrev) {
  const int d = static_cast<int>(q.rows());
  for (int i = 0; i < q.cols(); ++i) {
    std::vector<double> now(q.col(i).data(), q.col(i).data() + d);
    std::vector<double> before(qPrev.col(i).data(), qPrev.col(i).data() + d);
    EXPECT_EQ(monitor.add(i, k, now, before, k), FormationMonitor::Receipt::Accepted);
  }
  const std::vector<FormationSnapshot> done = monitor.takeCompleted();
  EXPECT_EQ(done.size(), 1u);
  return done.empty() ? FormationSnapshot() : done.front();
}

TEST(FormationMonitor, EachCongruentStretchSaysWhetherItIsTheMirrorImage) {
  // The hexagon at rest, as its mirror image, stretched (not congruent), then as desired: each
  // congruent stretch carries its own answer at every step (the test runs at a stretch's first
  // step; the others keep it), and the findings agree with findShape's own test.
  const Scenario s = loadScenario(test::configPath("hexagon"));
  const Formation f = makeFormation(s);
  Positions mirror = f.desiredShape();
  mirror.row(1) *= -1.0;
  const Positions desired = f.desiredShape();
  const Positions stretched = 1.5 * desired;
  FormationMonitor monitor(s);
  monitor.startAt(1, -1);  // at rest from step 1 on (step 0 takes the scenario's velocities)
  const std::vector<std::pair<const Positions*, bool>> run = {
      {&mirror, true}, {&mirror, true}, {&mirror, true}, {&stretched, false}, {&desired, false}, {&desired, false}};
  long k = 1;
  for (const auto& [q, mirrored] : run) {
    const FormationSnapshot snap = measureAt(monitor, k, *q, *q);
    EXPECT_EQ(snap.congruent, q != &stretched) << "step " << k;
    EXPECT_EQ(snap.shape.mirrored, mirrored) << "step " << k;
    // Converged means the desired shape (issue 50): the mirror image is congruent, not converged.
    EXPECT_EQ(snap.converged, q == &desired) << "step " << k;
    EXPECT_EQ(snap.congruentSince, q == &stretched ? -1 : q == &mirror ? 1 : 5) << "step " << k;
    EXPECT_EQ(snap.convergedStep, q == &desired ? 5 : -1) << "step " << k;
    const ShapeFindings alone = findShape(f, *q, Positions::Zero(2, 6), 1.0, snap.congruent, 0.01, 0.1);  // the defaults
    EXPECT_EQ(snap.shape.mirrored, alone.mirrored) << "step " << k;
    ++k;
  }
  // With `mirror: allowed` the mirror image is the desired shape too.
  Scenario either = s;
  either.mirrorAllowed = true;
  FormationMonitor lenient(either);
  lenient.startAt(1, -1);
  const FormationSnapshot allowed = measureAt(lenient, 1, mirror, mirror);
  EXPECT_TRUE(allowed.converged && allowed.shape.mirrored);
  EXPECT_EQ(allowed.convergedStep, 1);
  // A monitor restarted inside a congruent stretch tests it again.
  FormationMonitor restarted(s);
  restarted.startAt(k, 5);
  EXPECT_TRUE(measureAt(restarted, k, mirror, mirror).shape.mirrored);
}

TEST(FormationMonitorUnderCommands, MeasuresAsSimulateDoesAndConvergesWhileMoving) {
  const Scenario s = loadScenario(test::configPath("hexagon_manoeuvre"));  // travels, turns, grows to 1.5
  const CommandSchedule schedule = scheduleFromSegments(s.manoeuvre, s.timeStep);
  const Formation f = makeFormation(s);
  ManoeuvreIntegrator integ(f, s.initialPositions, s.initialVelocities, s.timeStep, s.dampingGain,
                            StartMethod::Variational, schedule);
  FormationMonitor monitor(s);  // takes the scenario's manoeuvre
  Scenario still = s;
  still.manoeuvre.clear();
  FormationMonitor unaware(still);  // the same states measured as if nothing were commanded
  Positions qPrev = s.initialPositions;
  FormationSnapshot last, lastUnaware;
  long congruentSteps = 0;
  for (long k = 0; k <= s.steps; ++k) {
    if (k > 0) {
      qPrev = integ.positions();
      integ.step();
    }
    const StepMetrics expected = measure(integ);
    last = measureAt(monitor, k, integ.positions(), qPrev);
    lastUnaware = measureAt(unaware, k, integ.positions(), qPrev);
    ASSERT_EQ(last.metrics.maxDistanceError, expected.maxDistanceError) << "step " << k;
    ASSERT_EQ(last.metrics.energy, expected.energy) << "step " << k;
    ASSERT_EQ(last.scale, integ.commandedScale()) << "step " << k;
    congruentSteps += last.converged ? 1 : 0;
  }
  // The last segment (t >= 24 s) moves at v* = (-1, 0) with s = 1.5: congruent within its 6 s.
  EXPECT_TRUE(last.converged);
  EXPECT_GT(last.convergedStep, 2400);
  EXPECT_LT(last.convergedStep, 2900);
  EXPECT_LT(last.metrics.maxDistanceError, 1e-3);
  for (Eigen::Index e = 0; e < last.edgeDistanceErrors.size(); ++e) {
    EXPECT_LT(std::abs(last.edgeDistanceErrors(e)), 1e-3) << "edge " << e;
  }
  // Measured against d_ij and standing still, the same run never looks formed.
  EXPECT_FALSE(lastUnaware.converged);
  EXPECT_GT(lastUnaware.metrics.maxDistanceError, 0.9);  // 0.5 d_ij, d_ij >= 2
  std::cout << "  hexagon_manoeuvre: congruent since step " << last.convergedStep << ", " << congruentSteps
            << " congruent steps of " << s.steps + 1 << ", final error " << last.metrics.maxDistanceError << " m\n";
}

/// q_k of the desired hexagon scaled by `scale`, turned by `rate` k h about its centroid and moved
/// by `velocity` k h.
Positions rigidMotion(const Formation& f, double scale, const Vector3& velocity, double rate, long k, double h) {
  const Positions& shape = f.desiredShape();
  const Eigen::Vector2d centroid = shape.rowwise().mean();
  const double angle = rate * static_cast<double>(k) * h;
  Eigen::Matrix2d turn;
  turn << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  Positions q(2, shape.cols());
  for (Eigen::Index i = 0; i < shape.cols(); ++i) {
    q.col(i) = centroid + scale * (turn * (shape.col(i) - centroid)) + velocity.head(2) * static_cast<double>(k) * h;
  }
  return q;
}

/// Whether step 50 of a rigid motion (scale, velocity, rate) is congruent under `commanded`.
bool congruentUnder(const Command& commanded, double scale, const Vector3& velocity, double rate) {
  Scenario s = loadScenario(test::configPath("hexagon_manoeuvre"));
  s.manoeuvre = {ManoeuvreSegment{0.0, commanded}};
  const Formation f = makeFormation(s);
  s.initialPositions = rigidMotion(f, scale, velocity, rate, 0, s.timeStep);
  s.initialVelocities = (s.initialPositions - rigidMotion(f, scale, velocity, rate, -1, s.timeStep)) / s.timeStep;
  FormationMonitor monitor(s);
  bool congruent = false;
  for (long k = 0; k <= 50; ++k) {
    const Positions q = rigidMotion(f, scale, velocity, rate, k, s.timeStep);
    const Positions qPrev = rigidMotion(f, scale, velocity, rate, k - 1, s.timeStep);
    congruent = measureAt(monitor, k, q, qPrev).converged;
  }
  return congruent;
}

TEST(FormationMonitorUnderCommands, CongruentOnlyWhenMovingAsCommanded) {
  const Command c = test::command({0.6, -0.4, 0.0}, {0, 0, 0.5}, 1.5);
  // Exactly as commanded (the difference quotient of the turn is off by about h w^2 r / 2).
  EXPECT_TRUE(congruentUnder(c, 1.5, c.velocity, 0.5));
  // 0.05 m/s behind the commanded velocity: within the 0.1 m/s threshold.
  EXPECT_TRUE(congruentUnder(c, 1.5, c.velocity - Vector3(0.05, 0, 0), 0.5));
  // 0.15 m/s behind: not congruent.
  EXPECT_FALSE(congruentUnder(c, 1.5, c.velocity - Vector3(0.15, 0, 0), 0.5));
  // Not turning (the outer agents lag w* |r| = 0.5 x 3 m/s).
  EXPECT_FALSE(congruentUnder(c, 1.5, c.velocity, 0.0));
  // The unscaled shape.
  EXPECT_FALSE(congruentUnder(c, 1.0, c.velocity, 0.5));
  // 1.5% larger than commanded: outside the 1% tolerance; 0.5% larger: inside.
  EXPECT_FALSE(congruentUnder(c, 1.5 * 1.015, c.velocity, 0.5));
  EXPECT_TRUE(congruentUnder(c, 1.5 * 1.005, c.velocity, 0.5));
  // A standing formation under a moving command, and a moving one under none.
  EXPECT_FALSE(congruentUnder(c, 1.5, Vector3::Zero(), 0.0));
  EXPECT_FALSE(congruentUnder(Command(), 1.0, c.velocity, 0.0));
  EXPECT_TRUE(congruentUnder(Command(), 1.0, Vector3::Zero(), 0.0));
}

TEST(CongruenceTracker, StaysAnchoredWhileAFormationTranslatesAndAgreesWithTheFullTest) {
  const Scenario s = loadScenario(test::configPath("hexagon_manoeuvre"));
  const Formation f = makeFormation(s);
  CongruenceTracker tracker(0.01, 0.1);
  const Vector3 velocity(1.0, 0.5, 0.0);
  for (long k = 0; k < 1000; ++k) {
    // A slow breathing on top of the translation keeps the test honest about the slack.
    const double breathe = 1.0 + 0.004 * std::sin(0.01 * static_cast<double>(k));
    const Positions q = rigidMotion(f, breathe, velocity, 0.0, k, s.timeStep);
    const Velocities relative = Velocities::Zero(2, f.agentCount());
    const bool full = f.congruenceSlack(q, 0.01) >= 0.0;
    ASSERT_EQ(tracker.check(f, q, relative), full) << "step " << k;
  }
  // 10 m of travel: without the centroid shift every step would be a full test.
  EXPECT_LT(tracker.fullTests(), 100);
  std::cout << "  1000 translating steps: " << tracker.fullTests() << " full pair tests\n";
}

}  // namespace
}  // namespace vf
