// The hand-point map (core/hand_point.hpp) and the simulated unicycle (core/unicycle_robot.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/robots/unicycle_command.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/robots/unicycle_robot.hpp"
#include "variational_formation_core/model/validation.hpp"

namespace vf {
namespace {

constexpr double kPi = 3.141592653589793;

template <typename F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "";
}

TEST(HandPoint, CommandGivesTheHandPointTheCommandedVelocity) {
  // p' = [c, -l s; s, l c] (v, w) must give back (vx, vy), at any heading.
  HandPointSettings s;
  s.handOffset = 0.15;
  for (double heading : {0.0, 0.7, -2.4, 3.1}) {
    const UnicycleCommand c = handPointCommand(s, heading, 0.3, -0.2);
    EXPECT_FALSE(c.saturated);
    const double px = std::cos(heading) * c.linear - s.handOffset * std::sin(heading) * c.angular;
    const double py = std::sin(heading) * c.linear + s.handOffset * std::cos(heading) * c.angular;
    EXPECT_NEAR(px, 0.3, 1e-15);
    EXPECT_NEAR(py, -0.2, 1e-15);
  }
}

TEST(HandPoint, SaturationKeepsTheDirectionAndRespectsBothLimits) {
  HandPointSettings s;  // l = 0.1, 2 m/s, 4 rad/s
  // Sideways at heading 0: w = 1/0.1 = 10 rad/s > 4: scaled by 0.4.
  const UnicycleCommand c = handPointCommand(s, 0.0, 0.5, 1.0);
  EXPECT_TRUE(c.saturated);
  EXPECT_LE(std::abs(c.linear), s.maxSpeed + 1e-15);
  EXPECT_NEAR(std::abs(c.angular), s.maxTurnRate, 1e-12);
  EXPECT_NEAR(c.linear, 0.4 * 0.5, 1e-12);  // the same factor on v: direction (0.5, 1) kept
  const UnicycleCommand fast = handPointCommand(s, 0.0, 5.0, 0.0);
  EXPECT_TRUE(fast.saturated);
  EXPECT_DOUBLE_EQ(fast.linear, 2.0);
}

TEST(HandPoint, OdometryPoseAndRejections) {
  const double yaw = 2.5;
  const PlanarPose pose = poseFromOdometry(1.0, -2.0, 0.0, 0.0, std::sin(yaw / 2), std::cos(yaw / 2));
  EXPECT_NEAR(pose.heading, yaw, 1e-14);
  double p[2];
  handPoint(pose, 0.1, p);
  EXPECT_NEAR(p[0], 1.0 + 0.1 * std::cos(yaw), 1e-15);
  const PlanarPose back = axleFromHandPoint(p, yaw, 0.1);
  EXPECT_NEAR(back.x, 1.0, 1e-15);
  EXPECT_NEAR(back.y, -2.0, 1e-15);
  EXPECT_NE(errorOf([] { poseFromOdometry(std::nan(""), 0, 0, 0, 0, 1); }).find("odometry: position and orientation must be finite"),
            std::string::npos);
  EXPECT_NE(errorOf([] { poseFromOdometry(0, 0, 0, 0, 0, 1.01); }).find("odometry: the orientation quaternion must have norm 1 (within 0.001), got norm 1.01"),
            std::string::npos);
  EXPECT_NO_THROW(poseFromOdometry(0, 0, 0, 0, 0, 1.0005));
  EXPECT_NE(errorOf([] { HandPointSettings s; s.handOffset = -0.1; handPointCommand(s, 0, 0, 0); })
                .find("hand_offset: must be"),
            std::string::npos);
}

TEST(HandPoint, SeededHeadingsAreReproducibleAndSpread) {
  EXPECT_EQ(drawInitialHeading(7, 3), drawInitialHeading(7, 3));
  EXPECT_NE(drawInitialHeading(7, 3), drawInitialHeading(7, 4));
  EXPECT_NE(drawInitialHeading(7, 3), drawInitialHeading(8, 3));
  for (int id = 0; id < 50; ++id) {
    const double h = drawInitialHeading(1, id);
    EXPECT_GE(h, -kPi);
    EXPECT_LT(h, kPi);
  }
  EXPECT_THROW(drawInitialHeading(1, -1), InvalidInput);
}

TEST(HandPoint, ScenarioInitialHeadingIsParsedAndValidated) {
  const std::string head =
      "name: t\ndimension: 2\nkappa: 1\ntime_step: 0.01\nsteps: 10\nedges: [[0, 1]]\nagents:\n";
  const Scenario s = parseScenario(head +
                                       "  - {id: 0, initial_position: [0, 0], desired_position: [0, 0], initial_heading: 1.5}\n"
                                       "  - {id: 1, initial_position: [1, 0], desired_position: [1, 0]}\n",
                                   "t");
  EXPECT_DOUBLE_EQ(initialHeading(s, 0), 1.5);
  EXPECT_DOUBLE_EQ(initialHeading(s, 1), 0.0);
  const Scenario none = parseScenario(head +
                                          "  - {id: 0, initial_position: [0, 0], desired_position: [0, 0]}\n"
                                          "  - {id: 1, initial_position: [1, 0], desired_position: [1, 0]}\n",
                                      "t");
  EXPECT_TRUE(none.initialHeadings.empty());
  EXPECT_DOUBLE_EQ(initialHeading(none, 1), 0.0);
  EXPECT_NE(errorOf([&] {
              parseScenario(head + "  - {id: 0, initial_position: [0, 0], desired_position: [0, 0], initial_heading: x}\n"
                                   "  - {id: 1, initial_position: [1, 0], desired_position: [1, 0]}\n",
                            "t");
            }).find("t: agents[0].initial_heading: expected a number"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              parseScenario("name: t\ndimension: 3\nkappa: 1\ntime_step: 0.01\nsteps: 10\nedges: [[0, 1]]\nagents:\n"
                            "  - {id: 0, initial_position: [0, 0, 0], desired_position: [0, 0, 0], initial_heading: 1}\n"
                            "  - {id: 1, initial_position: [1, 0, 0], desired_position: [1, 0, 0]}\n",
                            "t");
            }).find("initial_heading: only for planar"),
            std::string::npos);
}

// Reference: classical RK4 on (x, y, theta, v, w) with a tiny step.
PlanarPose rk4Reference(const UnicycleRobotSettings& s, PlanarPose p, double uv, double uw, double T) {
  double st[5] = {p.x, p.y, p.heading, 0.0, 0.0};
  const auto f = [&](const double* y, double* d) {
    d[0] = y[3] * std::cos(y[2]);
    d[1] = y[3] * std::sin(y[2]);
    d[2] = y[4];
    d[3] = (uv - y[3]) / s.lag;
    d[4] = (uw - y[4]) / s.lag;
  };
  const long n = 200000;
  const double dt = T / n;
  for (long i = 0; i < n; ++i) {
    double k1[5], k2[5], k3[5], k4[5], t[5];
    f(st, k1);
    for (int a = 0; a < 5; ++a) t[a] = st[a] + 0.5 * dt * k1[a];
    f(t, k2);
    for (int a = 0; a < 5; ++a) t[a] = st[a] + 0.5 * dt * k2[a];
    f(t, k3);
    for (int a = 0; a < 5; ++a) t[a] = st[a] + dt * k3[a];
    f(t, k4);
    for (int a = 0; a < 5; ++a) st[a] += dt / 6 * (k1[a] + 2 * k2[a] + 2 * k3[a] + k4[a]);
  }
  return {st[0], st[1], st[2]};
}

TEST(UnicycleRobot, MatchesAFineReferenceWhateverTheSplit) {
  UnicycleRobotSettings s;
  s.lag = 0.1;
  s.odometryNoise = 0.0;
  const PlanarPose start{0.5, -0.3, 0.4};
  const PlanarPose ref = rk4Reference(s, start, 1.2, 3.0, 2.0);
  for (double dt : {2.0, 0.01, 0.0137}) {
    UnicycleRobot robot(s, start, 1);
    robot.setCommand(1.2, 0.0, 3.0);
    for (double t = 0.0; t < 2.0 - 1e-12; t += dt) robot.advance(std::min(dt, 2.0 - t));
    EXPECT_NEAR(robot.pose().x, ref.x, 1e-9) << dt;
    EXPECT_NEAR(robot.pose().y, ref.y, 1e-9) << dt;
    EXPECT_NEAR(std::remainder(robot.pose().heading - ref.heading, 2 * kPi), 0.0, 1e-11) << dt;
  }
}

TEST(UnicycleRobot, WithoutLagDrivesTheExactArc) {
  UnicycleRobotSettings s;
  s.lag = 0.0;
  UnicycleRobot robot(s, {0.0, 0.0, 0.0}, 1);
  robot.setCommand(1.0, 0.0, 2.0);  // radius 0.5
  robot.advance(1.0);
  EXPECT_NEAR(robot.pose().x, 0.5 * std::sin(2.0), 1e-10);
  EXPECT_NEAR(robot.pose().y, 0.5 * (1 - std::cos(2.0)), 1e-10);
}

TEST(UnicycleRobot, LimitsLateralCommandAndBadInput) {
  UnicycleRobotSettings s;
  s.odometryNoise = 0.0;
  UnicycleRobot a(s, {0, 0, 0.3}, 1), b(s, {0, 0, 0.3}, 1);
  a.setCommand(0.5, 0.0, 1.0);
  b.setCommand(0.5, 3.0, 1.0);  // linear.y ignored
  a.advance(1.0);
  b.advance(1.0);
  EXPECT_EQ(a.pose().x, b.pose().x);
  EXPECT_EQ(a.pose().y, b.pose().y);
  UnicycleRobot c(s, {0, 0, 0}, 1);
  c.setCommand(10.0, 0.0, -10.0);
  EXPECT_EQ(c.commandedLinear(), s.maxSpeed);
  EXPECT_EQ(c.commandedAngular(), -s.maxTurnRate);
  for (int i = 0; i < 100; ++i) {
    c.advance(0.01);
    EXPECT_LE(std::abs(c.linearVelocity()), s.maxSpeed);
    EXPECT_LE(std::abs(c.angularVelocity()), s.maxTurnRate);
  }
  EXPECT_NE(errorOf([&] { c.setCommand(std::nan(""), 0, 0); }).find("command: must be finite"), std::string::npos);
  EXPECT_EQ(c.commandedLinear(), s.maxSpeed);  // unchanged
  EXPECT_NE(errorOf([&] { c.advance(-1); }).find("dt: must be"), std::string::npos);
  UnicycleRobotSettings bad;
  bad.maxTurnRate = 0.0;
  EXPECT_NE(errorOf([&] { UnicycleRobot r(bad, {0, 0, 0}, 1); }).find("max_turn_rate: must be"), std::string::npos);
  EXPECT_NE(errorOf([&] { UnicycleRobot r(s, {0, INFINITY, 0}, 1); }).find("initial pose: must be finite"),
            std::string::npos);
}

TEST(UnicycleRobot, SeededNoiseIsReproducible) {
  UnicycleRobotSettings s;
  s.headingNoise = 0.02;
  UnicycleRobot a(s, {1, 2, 0}, 42), b(s, {1, 2, 0}, 42), c(s, {1, 2, 0}, 43);
  double sum2 = 0.0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const PlanarPose pa = a.measuredPose(), pb = b.measuredPose(), pc = c.measuredPose();
    EXPECT_EQ(pa.x, pb.x);
    EXPECT_EQ(pa.heading, pb.heading);
    EXPECT_NE(pa.x, pc.x);
    sum2 += (pa.x - 1.0) * (pa.x - 1.0);
  }
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.01, 0.001);  // 4000 samples: relative standard error 1.1%
}

TEST(UnicycleRobot, HandPointTracksAConstantCommandedVelocityUnderTheLag) {
  // A 100 Hz loop: measure the heading, map the commanded hand-point velocity, advance.
  UnicycleRobotSettings s;
  s.lag = 0.1;
  s.odometryNoise = 0.0;
  HandPointSettings hand;
  UnicycleRobot robot(s, {0, 0, 2.0}, 1);  // facing away from the commanded direction
  const double ux = 0.4, uy = 0.1;
  double before[2], after[2];
  for (int k = 0; k < 300; ++k) {
    if (k == 299) handPoint(robot.pose(), hand.handOffset, before);
    const UnicycleCommand c = handPointCommand(hand, robot.pose().heading, ux, uy);
    robot.setCommand(c.linear, 0.0, c.angular);
    robot.advance(0.01);
  }
  handPoint(robot.pose(), hand.handOffset, after);
  // After 3 s (30 lags) the hand point moves at the commanded velocity.
  EXPECT_NEAR((after[0] - before[0]) / 0.01, ux, 1e-3);
  EXPECT_NEAR((after[1] - before[1]) / 0.01, uy, 1e-3);
  // And the body has turned towards it: the heading is the direction of travel.
  EXPECT_NEAR(std::remainder(robot.pose().heading - std::atan2(uy, ux), 2 * kPi), 0.0, 0.01);
}

}  // namespace
}  // namespace vf
