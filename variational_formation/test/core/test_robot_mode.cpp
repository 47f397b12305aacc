// Robot mode without ROS (core/robot_mode.hpp): the lag against the delay margin, the slow
// odometry correction, and closed loops of time-driven agents with simulated robots on the
// 7-agent ring of issue 20 (config/ring7.yaml: spacing 2 m, kappa 2, h 0.01 s, D* = 5 steps).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/robots/robot_mode.hpp"

namespace vf {
namespace {

const std::string kRing = std::string(VF_SOURCE_DIR) + "/config/ring7.yaml";

TEST(RobotLag, WarnsWhenTheLagExceedsTheMargin) {
  const Scenario ring = loadScenario(kRing);
  const RobotLagCheck slow = checkRobotLag(ring, 0.1, 0.01);
  EXPECT_EQ(slow.marginSteps, 5);  // delay_margin's prediction for this scenario
  EXPECT_TRUE(slow.exceeded);
  EXPECT_NE(slow.warning.find("robot lag 0.1 s plus one tick 0.01 s = 0.11 s exceeds the delay margin D* = 5 steps = 0.05 s"),
            std::string::npos)
      << slow.warning;
  EXPECT_NE(slow.warning.find("a larger kappa or a smaller h"), std::string::npos);
  EXPECT_EQ(slow.warning.find('\n'), std::string::npos);
  const RobotLagCheck fast = checkRobotLag(ring, 0.02, 0.01);  // 0.03 s < 0.05 s
  EXPECT_FALSE(fast.exceeded);
  EXPECT_TRUE(fast.warning.empty());
  EXPECT_THROW(checkRobotLag(ring, -0.1, 0.01), InvalidInput);
  EXPECT_THROW(checkRobotLag(ring, 0.1, 0.0), InvalidInput);
}

TEST(RobotLag, LinesNameTheOptionsAndRoundTheirNumbers) {
  const Scenario ring = loadScenario(kRing);
  // The sum: 0.1 + 0.02 is 0.12000000000000001 in doubles; the lines print 0.12.
  ASSERT_EQ(formatNumber(0.1 + 0.02), "0.12000000000000001");
  const RobotLagCheck odometry = checkRobotLag(ring, 0.1, 0.02, RobotFeedback::Odometry, "~");
  EXPECT_TRUE(odometry.applies);
  EXPECT_TRUE(odometry.exceeded);
  EXPECT_EQ(odometry.warning.rfind("~feedback odometry, ~robot_lag: robot lag 0.1 s plus one tick 0.02 s = 0.12 s "
                                   "exceeds the delay margin D* = 5 steps = 0.05 s (kappa 2, h 0.01): ",
                                   0),
            0u)
      << odometry.warning;
  EXPECT_NE(odometry.warning.find("or use ~feedback integrated"), std::string::npos) << odometry.warning;
  EXPECT_TRUE(odometry.info.empty());
}

TEST(RobotLag, WithIntegratedFeedbackTheMarginIsOnlyReported) {
  // The lag reaches the formation only through the correction (doc/robots.md): no warning.
  const Scenario ring = loadScenario(kRing);
  const RobotLagCheck integrated = checkRobotLag(ring, 0.1, 0.02, RobotFeedback::Integrated, "~");
  EXPECT_FALSE(integrated.applies);
  EXPECT_TRUE(integrated.exceeded);  // the numbers are the same; they do not bound this loop
  EXPECT_EQ(integrated.marginSteps, 5);
  EXPECT_TRUE(integrated.warning.empty()) << integrated.warning;
  EXPECT_EQ(integrated.info.rfind("~feedback integrated: robot lag 0.1 s plus one tick 0.02 s = 0.12 s exceeds "
                                  "the delay margin D* = 5 steps = 0.05 s (kappa 2, h 0.01); the margin bounds "
                                  "~robot_lag only with ~feedback odometry",
                                  0),
            0u)
      << integrated.info;
  EXPECT_NE(integrated.info.find("~correction_time"), std::string::npos);
  // Within the margin, either feedback: one line to inform (no scan found an instability).
  const RobotLagCheck within = checkRobotLag(ring, 0.02, 0.01, RobotFeedback::Odometry, "~");
  EXPECT_TRUE(within.warning.empty());
  EXPECT_EQ(within.info.rfind("~feedback odometry, ~robot_lag: robot lag 0.02 s plus one tick 0.01 s = 0.03 s is "
                              "within the delay margin",
                              0),
            0u)
      << within.info;
}

TEST(RobotLag, CorrectionIsAFirstOrderPull) {
  std::vector<double> out;
  correctedPosition({0.0, 1.0}, {1.0, 1.0}, 0.01, 0.0, out);
  EXPECT_EQ(out, (std::vector<double>{1.0, 1.0}));  // Tc = 0: the odometry itself
  // n ticks of h with Tc: the gap shrinks by e^{-n h / Tc}.
  std::vector<double> q = {0.0};
  for (int k = 0; k < 500; ++k) {
    correctedPosition(q, {1.0}, 0.01, 5.0, out);
    q = out;
  }
  EXPECT_NEAR(1.0 - q[0], std::exp(-1.0), 1e-12);
  EXPECT_THROW(correctedPosition({0.0}, {1.0}, 0.01, -1.0, out), InvalidInput);
  EXPECT_THROW(correctedPosition({0.0}, {NAN}, 0.01, 1.0, out), InvalidInput);
  EXPECT_THROW(correctedPosition({0.0}, {1.0, 2.0}, 0.01, 1.0, out), InvalidInput);
}

RobotLoopResult run(RobotKinematics kinematics, RobotFeedback feedback, double lag) {
  RobotLoopSettings s;
  s.kinematics = kinematics;
  s.feedback = feedback;
  s.lag = lag;
  const RobotLoopResult r = runRobotLoop(loadScenario(kRing), s);
  std::printf("%-9s %-10s lag %.1f s: converged %s at %.2f s, final error %.4f m (max over the last second %.4f m), "
              "saturated commands %ld, largest turn %.2f rad\n",
              kinematics == RobotKinematics::Unicycle ? "unicycle" : "holonomic",
              feedback == RobotFeedback::Integrated ? "integrated" : "odometry", lag,
              r.convergedStep >= 0 ? "yes" : "no", r.convergedTime, r.finalError, r.maxErrorLastSecond,
              r.saturatedCommands, r.maxHeadingChange);
  return r;
}

TEST(RobotLoop, OdometryFeedbackBeyondTheMarginNeverForms) {
  // The failure of issue 20: lag 0.1 s + one tick > D* h = 0.05 s.
  const RobotLoopResult r = run(RobotKinematics::Holonomic, RobotFeedback::Odometry, 0.1);
  EXPECT_EQ(r.convergedStep, -1);
  EXPECT_GT(r.finalError, 0.1);
}

TEST(RobotLoop, IntegratedFeedbackFormsWithinOneCentimetre) {
  for (RobotKinematics k : {RobotKinematics::Holonomic, RobotKinematics::Unicycle}) {
    for (double lag : {0.1, 0.3}) {
      const RobotLoopResult r = run(k, RobotFeedback::Integrated, lag);
      EXPECT_GE(r.convergedStep, 0) << lag;
      EXPECT_LE(r.maxErrorLastSecond, 0.01) << lag;
      if (k == RobotKinematics::Unicycle) {
        EXPECT_GT(r.maxHeadingChange, 0.5) << "the robots turned";
      }
    }
  }
}

TEST(RobotLoop, TheOtherCasesForTheTable) {
  // Printed for doc/robots.md; odometry feedback at 0.3 s is even further beyond the margin.
  EXPECT_EQ(run(RobotKinematics::Holonomic, RobotFeedback::Odometry, 0.3).convergedStep, -1);
  EXPECT_EQ(run(RobotKinematics::Unicycle, RobotFeedback::Odometry, 0.1).convergedStep, -1);
  EXPECT_EQ(run(RobotKinematics::Unicycle, RobotFeedback::Odometry, 0.3).convergedStep, -1);
}

TEST(RobotLoop, BadSettingsAreRejected) {
  RobotLoopSettings s;
  s.correctionTime = -1.0;
  EXPECT_THROW(runRobotLoop(loadScenario(kRing), s), InvalidInput);
  Scenario unbounded = loadScenario(kRing);
  unbounded.steps = 0;
  EXPECT_THROW(runRobotLoop(unbounded, RobotLoopSettings{}), InvalidInput);
}

}  // namespace
}  // namespace vf
