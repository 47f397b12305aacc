// The monitor's measurement of the robots (RobotShapeWatch): the robots' points from odometry
// (hand points for unicycles), averaged over a window, their edge and shape errors, the in-shape
// stretch, and the verdict of a robot-mode run (robotModeOutcome). Expected errors are computed by
// hand from the geometry in the comments, not read from the code.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/robots/robot_shape_watch.hpp"
#include "variational_formation_core/agents/run_verdict.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "test_support.hpp"

namespace vf {
namespace {

constexpr double kPi = 3.141592653589793;

// A regular hexagon of side 1 (agent k at angle k 60 degrees, radius 1), the shipped hexagon's
// 9 edges: the 6 sides and the chords 0-2, 0-3, 0-4. h = 0.01 s.
std::string hexagonYaml(bool requireConvergence = false) {
  std::string agents;
  for (int k = 0; k < 6; ++k) {
    const double a = k * kPi / 3.0;
    char line[200];
    std::snprintf(line, sizeof line, "  - {id: %d, initial_position: [%.17g, %.17g], desired_position: [%.17g, %.17g]}\n",
                  k, 1.2 * std::cos(a), 1.2 * std::sin(a), std::cos(a), std::sin(a));
    agents += line;
  }
  return "name: hex\ndimension: 2\nkappa: 2\ntime_step: 0.01\nsteps: 1000\nagents:\n" + agents +
         "edges: [[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [5, 0], [0, 2], [0, 3], [0, 4]]\n" +
         (requireConvergence ? "require_convergence: true\n" : "");
}

const Scenario& hexagon() {
  static const Scenario s = parseScenario(hexagonYaml(), "hex.yaml");
  return s;
}

// The desired hexagon turned by `angle` about the origin and moved by (dx, dy) [m].
Positions moved(double angle, double dx, double dy) {
  Positions q = hexagon().desiredPositions;
  for (Eigen::Index i = 0; i < q.cols(); ++i) {
    const double x = q(0, i), y = q(1, i);
    q(0, i) = std::cos(angle) * x - std::sin(angle) * y + dx;
    q(1, i) = std::sin(angle) * x + std::cos(angle) * y + dy;
  }
  return q;
}

// Odometry of a holonomic robot at (x, y), no rotation.
void feed(RobotShapeWatch& w, int id, double t, double x, double y) { w.addOdometry(id, t, x, y, 0.0, 0.0, 0.0, 0.0, 1.0); }

void feedAll(RobotShapeWatch& w, double t, const Positions& q) {
  for (int i = 0; i < q.cols(); ++i) feed(w, i, t, q(0, i), q(1, i));
}

using test::thrown;

TEST(RobotShapeWatch, RobotsOnTheDesiredShapeTurnedAndMovedAreInShape) {
  RobotShapeWatch w(hexagon(), RobotShapeSettings{});
  feedAll(w, 10.0, moved(0.7, 4.0, -3.0));
  const RobotShapeStep& r = w.observe(40, 10.0, 1.0);
  ASSERT_TRUE(r.measured) << r.unmeasured;
  EXPECT_TRUE(r.findings.congruent);
  EXPECT_LT(r.findings.maxEdgeError, 1e-12);
  EXPECT_LT(r.findings.shapeError, 1e-12);
  EXPECT_EQ(r.inShapeSince, 40);
  const ShapeOutcome o = w.outcome(0.01);
  EXPECT_EQ(o.verdict, ShapeVerdict::DesiredShape);
  EXPECT_EQ(o.convergedStep, 40);
  EXPECT_EQ(o.line, "converged to the desired shape at step 40 (t = 0.400 s)");
}

TEST(RobotShapeWatch, OneRobotFiveCentimetresOffIsNotInShapeWithItsErrors) {
  // Robot 0 5 cm further out along its radius (the whole shape turned by 0.7 rad and moved):
  // edge 0-3 is 2.05 m instead of 2 m, the largest error of any pair (0.05 m); edge 0-1 is
  // sqrt(0.55^2 + 0.75) = sqrt(1.0525) m, 0.0259 m long: outside 1% of 1 m, so the edges have not
  // converged either.
  RobotShapeWatch w(hexagon(), RobotShapeSettings{});
  Positions q = moved(0.7, 4.0, -3.0);
  q(0, 0) += 0.05 * std::cos(0.7);
  q(1, 0) += 0.05 * std::sin(0.7);
  feedAll(w, 10.0, q);
  const RobotShapeStep& r = w.observe(40, 10.0, 1.0);
  ASSERT_TRUE(r.measured);
  EXPECT_FALSE(r.findings.congruent);
  EXPECT_FALSE(r.findings.edgesWithin);
  EXPECT_NEAR(r.findings.maxEdgeError, 0.05, 1e-12);
  EXPECT_NEAR(r.findings.shapeError, 0.05, 1e-12);
  EXPECT_EQ(r.inShapeSince, -1);
  const ShapeOutcome o = w.outcome(0.01);
  EXPECT_EQ(o.verdict, ShapeVerdict::NotConverged);
  EXPECT_EQ(o.line, "not converged (the robots, from odometry: max distance error 0.05 m, shape error 0.05 m)");
  // Against a commanded scale of 1.025 the same points are off differently: edge 0-3 should be
  // 2.05 m, which it is; edge 0-1 is sqrt(1.0525) = 1.02591 m, 0.9 mm long; the sides 1-2, 2-3,
  // 3-4, 4-5 (1 m) are 0.025 m short of 1.025 m, the largest error.
  const RobotShapeStep& scaled = w.observe(41, 10.0, 1.025);
  EXPECT_NEAR(scaled.findings.maxEdgeError, 0.025, 1e-12);
}

TEST(RobotShapeWatch, UnicyclesAreMeasuredAtTheirHandPoints) {
  // Axles 0.2 m behind hand points that form the shape, at headings 0.3 k rad: the hand points are
  // in shape; the axles, which this test also feeds as holonomic robots, are not.
  RobotShapeSettings s;
  s.kinematics = RobotKinematics::Unicycle;
  s.handOffset = 0.2;
  RobotShapeWatch unicycles(hexagon(), s), axles(hexagon(), RobotShapeSettings{});
  const Positions hand = moved(-1.1, 0.5, 2.0);
  for (int i = 0; i < 6; ++i) {
    const double theta = 0.3 * i;
    const double x = hand(0, i) - 0.2 * std::cos(theta), y = hand(1, i) - 0.2 * std::sin(theta);
    unicycles.addOdometry(i, 1.0, x, y, 0.0, 0.0, 0.0, std::sin(theta / 2), std::cos(theta / 2));
    feed(axles, i, 1.0, x, y);
  }
  const RobotShapeStep& r = unicycles.observe(5, 1.0, 1.0);
  EXPECT_TRUE(r.findings.congruent);
  EXPECT_LT(r.findings.shapeError, 1e-12);
  EXPECT_LT((unicycles.points() - hand).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_FALSE(axles.observe(5, 1.0, 1.0).findings.congruent);
}

TEST(RobotShapeWatch, OdometryIsAveragedOverTheNewestWindow) {
  RobotShapeSettings s;
  s.window = 0.5;
  RobotShapeWatch w(hexagon(), s);
  const Positions q = moved(0.0, 0.0, 0.0);
  // At t = 0 robot 0 is 0.3 m off; from t = 1 on its odometry jumps +-2 cm about the true point
  // (noise far beyond 1% of an edge), 100 Hz, an even number of samples in the window.
  feed(w, 0, 0.0, q(0, 0) + 0.3, q(1, 0));
  for (int k = 0; k <= 50; ++k) {
    const double t = 1.0 + 0.01 * k;
    feed(w, 0, t, q(0, 0) + (k % 2 ? 0.02 : -0.02), q(1, 0) + (k % 2 ? -0.02 : 0.02));
    for (int i = 1; i < 6; ++i) feed(w, i, t, q(0, i), q(1, i));
  }
  // The window [1.0, 1.5] holds k = 0..50: 26 samples at -2 cm, 25 at +2 cm in x: the mean is
  // off by (25 - 26) 0.02 / 51 = -0.39 mm in x and +0.39 mm in y, and the sample at t = 0 is gone.
  const RobotShapeStep& r = w.observe(7, 1.5, 1.0);
  EXPECT_NEAR(w.points()(0, 0), q(0, 0) - 0.02 / 51, 1e-12);
  EXPECT_NEAR(w.points()(1, 0), q(1, 0) + 0.02 / 51, 1e-12);
  EXPECT_TRUE(r.findings.congruent);
  EXPECT_LT(r.findings.maxEdgeError, 0.001);
  // Without averaging (the newest sample alone, +2 cm, -2 cm) robot 0 is off by 2.8 cm: not in shape.
  RobotShapeSettings raw;
  raw.window = 1e-6;
  RobotShapeWatch single(hexagon(), raw);
  feedAll(single, 1.5, q);
  feed(single, 0, 1.6, q(0, 0) + 0.02, q(1, 0) - 0.02);
  EXPECT_FALSE(single.observe(7, 1.6, 1.0).findings.congruent);
  EXPECT_EQ(single.points()(0, 0), q(0, 0) + 0.02);
}

TEST(RobotShapeWatch, TheInShapeStretchIsTheOneHoldingAtTheEnd) {
  RobotShapeWatch w(hexagon(), RobotShapeSettings{});
  const Positions in = moved(0.2, 1.0, 1.0);
  Positions off = in;
  off(0, 2) += 0.1;
  const Positions* sequence[] = {&off, &in, &in, &off, &in, &in};
  for (int k = 0; k < 6; ++k) {
    const double t = 2.0 * k;  // each beyond the window: one sample counts
    feedAll(w, t, *sequence[k]);
    const RobotShapeStep& r = w.observe(10 + k, t, 1.0);
    const long expected[] = {-1, 11, 11, -1, 14, 14};
    EXPECT_EQ(r.inShapeSince, expected[k]) << "step " << 10 + k;
  }
  EXPECT_EQ(w.outcome(0.01).convergedStep, 14);
}

TEST(RobotShapeWatch, SaysWhichRobotItWaitsForAndWhichFellSilent) {
  RobotShapeWatch w(hexagon(), RobotShapeSettings{});
  const Positions q = moved(0.0, 0.0, 0.0);
  for (int i : {0, 1, 2, 4, 5}) feed(w, i, 0.0, q(0, i), q(1, i));
  EXPECT_EQ(w.unheard(), std::vector<int>{3});
  const RobotShapeStep& r = w.observe(0, 0.0, 1.0);
  EXPECT_FALSE(r.measured);
  EXPECT_EQ(r.unmeasured, "no odometry from robot_3");
  EXPECT_TRUE(std::isnan(r.findings.maxEdgeError));
  ShapeOutcome o = w.outcome(0.01);
  EXPECT_EQ(o.verdict, ShapeVerdict::NotConverged);
  EXPECT_EQ(o.line, "not converged (the robots: no odometry from robot_3)");
  // Robot 3 comes; at t = 3 robots 3 and 5 have been silent since t = 0 and 1.
  feed(w, 3, 0.0, q(0, 3), q(1, 3));
  for (int i : {0, 1, 2, 4}) feed(w, i, 3.0, q(0, i), q(1, i));
  feed(w, 5, 1.0, q(0, 5), q(1, 5));
  EXPECT_EQ(w.silent(3.0), (std::vector<int>{3, 5}));
  EXPECT_EQ(w.observe(1, 3.0, 1.0).unmeasured, "robots 3, 5 silent for up to 3.0 s");
  EXPECT_EQ(w.outcome(0.01).line, "not converged (the robots: robots 3, 5 silent for up to 3.0 s)");
}

TEST(RobotShapeWatch, BadOdometryAndSettingsAreRefusedInOneLine) {
  RobotShapeWatch w(hexagon(), RobotShapeSettings{});
  EXPECT_EQ(thrown([&] { feed(w, 1, 0.0, NAN, 0.0); }).rfind("robot_1: odometry: ", 0), 0u);
  EXPECT_EQ(thrown([&] { w.addOdometry(2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0); }).rfind("robot_2: odometry: ", 0),
            0u);
  EXPECT_EQ(thrown([&] { feed(w, 2, NAN, 0.0, 0.0); }), "robot_2: odometry: time must be finite, got nan");
  EXPECT_EQ(thrown([&] { feed(w, 6, 0.0, 0.0, 0.0); }), "robot_6: no such robot (the scenario has 6)");
  EXPECT_EQ(w.unheard(), (std::vector<int>{0, 1, 2, 3, 4, 5}));  // nothing was kept
  RobotShapeSettings s;
  s.window = 0.0;
  EXPECT_EQ(thrown([&] { RobotShapeWatch(hexagon(), s); }).rfind("robots_window: must be", 0), 0u);
  s = RobotShapeSettings{};
  s.kinematics = RobotKinematics::Unicycle;
  s.handOffset = -0.1;
  EXPECT_EQ(thrown([&] { RobotShapeWatch(hexagon(), s); }).rfind("hand_offset: must be", 0), 0u);
}

TEST(RobotModeOutcome, TheLaterOfTheTwoOrTheRobotsWhenTheyAreWorse) {
  ShapeFindings good;
  good.congruent = good.edgesWithin = good.atRest = true;
  const ShapeOutcome agents = shapeOutcome(good, 100, false, 0.01);
  ShapeOutcome robots = shapeOutcome(good, 150, false, 0.01);
  ShapeOutcome o = robotModeOutcome(agents, robots, 0.01);
  EXPECT_EQ(o.verdict, ShapeVerdict::DesiredShape);
  EXPECT_EQ(o.convergedStep, 150);
  EXPECT_EQ(o.line, "converged to the desired shape at step 150 (t = 1.500 s); the robots (odometry) from step 150, "
                    "the agents from step 100");
  robots = shapeOutcome(good, 40, false, 0.01);  // robots measured in shape before the agents: the agents' step
  EXPECT_EQ(robotModeOutcome(agents, robots, 0.01).convergedStep, 100);

  // The robots 5 cm off while the agents converged: not converged, with the robots' error, which
  // the run's reason then gives.
  RobotShapeWatch w(hexagon(), RobotShapeSettings{});
  Positions q = moved(0.0, 0.0, 0.0);
  q(0, 0) += 0.05;
  feedAll(w, 0.0, q);
  w.observe(3, 0.0, 1.0);
  o = robotModeOutcome(agents, w.outcome(0.01), 0.01);
  EXPECT_EQ(o.verdict, ShapeVerdict::NotConverged);
  EXPECT_EQ(o.convergedStep, -1);
  EXPECT_EQ(o.line, "not converged (the robots, from odometry: max distance error 0.05 m, shape error 0.05 m)");
  const RunVerdict v = finishedRunVerdict(parseScenario(hexagonYaml(true), "hex.yaml"), o);
  EXPECT_FALSE(v.succeeded);
  EXPECT_NE(v.reason.find("final max distance error 0.05 m"), std::string::npos) << v.reason;

  // The robots with every edge right but not every pair while the agents are in the desired shape:
  // they have not caught up (their speeds are not measured), still settling, not folded; with the
  // agents folded too, folded. Robots in the mirror image say so.
  RobotShapeWatch behind(hexagon(), RobotShapeSettings{});
  Positions folded = moved(0.0, 0.0, 0.0);
  folded.col(1) << 0.0, 0.0;  // agent 1 (linked to 0 and 2 only) reflected through the chord 0-2
  feedAll(behind, 0.0, folded);
  behind.observe(3, 0.0, 1.0);
  const ShapeOutcome robotsFolded = behind.outcome(0.01);
  EXPECT_EQ(robotsFolded.verdict, ShapeVerdict::Folded);
  EXPECT_EQ(robotsFolded.line, "not converged: folded (the robots, from odometry: every edge within tolerance but not "
                               "every pair; shape error 1 m)");
  o = robotModeOutcome(agents, robotsFolded, 0.01);
  EXPECT_EQ(o.verdict, ShapeVerdict::StillSettling);
  EXPECT_EQ(o.line, "not converged: still settling at the last step (the robots, from odometry, behind the agents, "
                    "which are in the desired shape: shape error 1 m)");
  ShapeFindings foldedAgents;
  foldedAgents.edgesWithin = foldedAgents.atRest = true;
  EXPECT_EQ(robotModeOutcome(shapeOutcome(foldedAgents, -1, false, 0.01), robotsFolded, 0.01).verdict,
            ShapeVerdict::Folded);
  RobotShapeWatch mirrored(hexagon(), RobotShapeSettings{});
  Positions mirror = moved(0.0, 0.0, 0.0);
  mirror.row(1) *= -1.0;
  feedAll(mirrored, 0.0, mirror);
  mirrored.observe(5, 0.0, 1.0);
  EXPECT_EQ(robotModeOutcome(agents, mirrored.outcome(0.01), 0.01).line,
            "not converged: the mirror image of the desired shape (the robots, from odometry, from step 5; mirror: "
            "forbidden)");

  // The agents not converged (blocked) decide, whatever the robots.
  const ShapeOutcome blocked = blockedShapeOutcome(agents, "blocked: agents 2, 4");
  EXPECT_EQ(robotModeOutcome(blocked, robots, 0.01).line, "not converged (blocked: agents 2, 4)");
}

}  // namespace
}  // namespace vf
