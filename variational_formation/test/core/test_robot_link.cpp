// RobotLink: the agent's side of robot mode (odometry in, cmd_vel out), checked against the
// hand-point map and correctedPosition written out by hand.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/robots/robot_link.hpp"
#include "test_support.hpp"

namespace vf {
namespace {

constexpr double kPi = 3.141592653589793;

using test::thrown;

RobotLinkSettings unicycle(RobotFeedback feedback) {
  RobotLinkSettings s;
  s.kinematics = RobotKinematics::Unicycle;
  s.feedback = feedback;
  s.hand.handOffset = 0.2;
  return s;
}

TEST(RobotLink, ParsesTheWordsAndNamesTheParameterOfABadOne) {
  EXPECT_EQ(parseKinematics("unicycle"), RobotKinematics::Unicycle);
  EXPECT_EQ(parseKinematics("holonomic"), RobotKinematics::Holonomic);
  EXPECT_EQ(parseFeedback("odometry"), RobotFeedback::Odometry);
  EXPECT_EQ(parseFeedback("integrated"), RobotFeedback::Integrated);
  EXPECT_EQ(thrown([] { parseKinematics("tank"); }), "kinematics: expected holonomic or unicycle, got 'tank'");
  EXPECT_EQ(thrown([] { parseFeedback("gps"); }), "feedback: expected integrated or odometry, got 'gps'");
  EXPECT_STREQ(kinematicsName(RobotKinematics::Unicycle), "unicycle");
  EXPECT_STREQ(feedbackName(RobotFeedback::Odometry), "odometry");
}

TEST(RobotLink, RefusesBadSettingsNamingTheParameter) {
  RobotLinkSettings s = unicycle(RobotFeedback::Integrated);
  s.hand.handOffset = -0.1;
  EXPECT_EQ(thrown([&] { RobotLink(s, 2, 0.01); }).rfind("hand_offset:", 0), 0u);
  s = unicycle(RobotFeedback::Integrated);
  s.hand.maxTurnRate = 0.0;
  EXPECT_EQ(thrown([&] { RobotLink(s, 2, 0.01); }).rfind("max_turn_rate:", 0), 0u);
  s = unicycle(RobotFeedback::Integrated);
  EXPECT_EQ(thrown([&] { RobotLink(s, 3, 0.01); }).rfind("kinematics: unicycle robots drive on the plane", 0), 0u);
  s = RobotLinkSettings{};
  s.lag = -1.0;
  EXPECT_EQ(thrown([&] { RobotLink(s, 2, 0.01); }).rfind("robot_lag:", 0), 0u);
  s = RobotLinkSettings{};
  s.correctionTime = NAN;
  EXPECT_EQ(thrown([&] { RobotLink(s, 2, 0.01); }).rfind("correction_time:", 0), 0u);
  s = RobotLinkSettings{};
  s.trackingGain = INFINITY;
  EXPECT_EQ(thrown([&] { RobotLink(s, 2, 0.01); }).rfind("tracking_gain:", 0), 0u);
  // A holonomic robot has no hand point: its limits are not read.
  s = RobotLinkSettings{};
  s.hand.handOffset = -1.0;
  EXPECT_EQ(thrown([&] { RobotLink(s, 3, 0.01); }), "");
}

TEST(RobotLink, BadOdometryIsRefusedAndLeavesTheMeasurement) {
  RobotLink link(unicycle(RobotFeedback::Odometry), 2, 0.01);
  EXPECT_FALSE(link.measured());
  std::vector<double> out;
  EXPECT_EQ(thrown([&] { link.startPosition({0.0, 0.0}, out); }), "robot: no odometry yet");
  EXPECT_EQ(thrown([&] { link.measureOdometry(NAN, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0); }).rfind("odometry:", 0), 0u);
  EXPECT_EQ(thrown([&] { link.measureOdometry(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.5); }).rfind("odometry: the orientation", 0),
            0u);
  EXPECT_FALSE(link.measured());
  // Yaw pi/2: the hand point is l straight ahead along +y.
  link.measureOdometry(1.0, 2.0, 0.0, 0.0, 0.0, std::sin(kPi / 4), std::cos(kPi / 4));
  ASSERT_TRUE(link.measured());
  EXPECT_NEAR(link.measuredPoint()[0], 1.0, 1e-15);
  EXPECT_NEAR(link.measuredPoint()[1], 2.2, 1e-15);
  EXPECT_NEAR(link.heading(), kPi / 2, 1e-15);
  EXPECT_NE(thrown([&] { link.measureOdometry(5.0, 5.0, 0.0, 0.0, 0.0, 0.0, 2.0); }), "");
  EXPECT_NEAR(link.measuredPoint()[1], 2.2, 1e-15);  // unchanged by the refused message
}

TEST(RobotLink, HolonomicOdometryIsThePositionAndZCountsIn3D) {
  RobotLink planar(RobotLinkSettings{}, 2, 0.01);
  planar.measureOdometry(1.0, -2.0, 7.0, 0.0, 0.0, 0.0, 1.0);
  EXPECT_EQ(planar.measuredPoint(), (std::vector<double>{1.0, -2.0}));
  RobotLink spatial(RobotLinkSettings{}, 3, 0.01);
  spatial.measureOdometry(1.0, -2.0, 7.0, 0.0, 0.0, 0.0, 1.0);
  EXPECT_EQ(spatial.measuredPoint(), (std::vector<double>{1.0, -2.0, 7.0}));
  EXPECT_NE(thrown([&] { spatial.measureOdometry(1.0, -2.0, NAN, 0.0, 0.0, 0.0, 1.0); }), "");
}

TEST(RobotLink, OdometryFeedbackStartsFromTheMeasurementAndSendsTheVelocity) {
  RobotLinkSettings s;
  s.feedback = RobotFeedback::Odometry;
  RobotLink link(s, 2, 0.01);
  link.measurePoint({1.0, 1.0});
  std::vector<double> start;
  link.startPosition({5.0, 5.0}, start);
  EXPECT_EQ(start, (std::vector<double>{1.0, 1.0}));
  const RobotLink::Command c = link.command({0.3, -0.4}, {1.0, 1.0});
  EXPECT_EQ(c.linear[0], 0.3);
  EXPECT_EQ(c.linear[1], -0.4);
  EXPECT_EQ(c.linear[2], 0.0);
  EXPECT_EQ(c.angular, 0.0);
}

TEST(RobotLink, IntegratedFeedbackPullsSlowlyAndTracksTheIntegratedPosition) {
  RobotLinkSettings s;  // integrated, Tc = 5 s, lag 0.1 s: k_p = 1 / (4 (0.1 + 0.01))
  RobotLink link(s, 2, 0.01);
  EXPECT_DOUBLE_EQ(link.trackingGain(), 1.0 / 0.44);
  link.measurePoint({1.0, 0.0});
  std::vector<double> start;
  link.startPosition({0.0, 0.0}, start);
  const double pull = 1.0 - std::exp(-0.01 / 5.0);
  EXPECT_NEAR(start[0], pull, 1e-16);
  EXPECT_EQ(start[1], 0.0);
  const RobotLink::Command c = link.command({0.5, 0.0}, {0.2, 0.1});
  EXPECT_NEAR(c.linear[0], 0.5 + (0.2 - 1.0) / 0.44, 1e-15);
  EXPECT_NEAR(c.linear[1], 0.1 / 0.44, 1e-15);
  s.trackingGain = 2.0;
  RobotLink fixed(s, 2, 0.01);
  EXPECT_EQ(fixed.trackingGain(), 2.0);
}

TEST(RobotLink, UnicycleCommandMovesTheHandPointAsAskedAndNeverSideways) {
  RobotLink link(unicycle(RobotFeedback::Odometry), 2, 0.01);
  const double heading = 0.7;
  link.measurePose({0.0, 0.0, heading});
  const double vx = 0.3, vy = -0.2;
  const RobotLink::Command c = link.command({vx, vy}, link.measuredPoint());
  EXPECT_EQ(c.linear[1], 0.0);
  EXPECT_EQ(c.linear[2], 0.0);
  EXPECT_FALSE(c.saturated);
  // p' = [cos, -l sin; sin, l cos] (v, w) gives back the asked velocity.
  const double l = 0.2;
  EXPECT_NEAR(std::cos(heading) * c.linear[0] - l * std::sin(heading) * c.angular, vx, 1e-15);
  EXPECT_NEAR(std::sin(heading) * c.linear[0] + l * std::cos(heading) * c.angular, vy, 1e-15);
  EXPECT_EQ(link.saturatedCommands(), 0);
  // Sideways at 2 m/s needs w = 10 rad/s > 4: scaled down in both, direction kept.
  const RobotLink::Command fast = link.command({-2.0 * std::sin(heading), 2.0 * std::cos(heading)}, link.measuredPoint());
  EXPECT_TRUE(fast.saturated);
  EXPECT_NEAR(std::abs(fast.angular), 4.0, 1e-12);
  EXPECT_EQ(link.saturatedCommands(), 1);
  EXPECT_EQ(link.commands(), 2);
}

}  // namespace
}  // namespace vf
