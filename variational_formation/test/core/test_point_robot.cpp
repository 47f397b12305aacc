// PointRobot: exact first-order lag with speed and acceleration limits, seeded odometry noise.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <string>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/robots/point_robot.hpp"

namespace vf {
namespace {

double norm(const std::vector<double>& x) { return std::sqrt(std::inner_product(x.begin(), x.end(), x.begin(), 0.0)); }

TEST(PointRobot, LagStepResponseIsTheExactExponential) {
  const double tau = 0.1;
  for (const std::vector<double>& u : {std::vector<double>{1.0, -0.5}, std::vector<double>{0.3, 0.2, -0.7}}) {
    // Limits far away: |u - v| <= |u| < maxAcceleration tau.
    PointRobot robot({tau, 10.0, 1000.0, 0.0}, std::vector<double>(u.size(), 1.0), 1);
    robot.setCommand(u);
    for (int k = 1; k <= 200; ++k) {
      robot.advance(0.01);
      const double t = 0.01 * k, decay = std::exp(-t / tau);
      for (std::size_t a = 0; a < u.size(); ++a) {
        ASSERT_NEAR(robot.velocity()[a], u[a] * (1.0 - decay), 1e-14) << t;
        ASSERT_NEAR(robot.position()[a], 1.0 + u[a] * (t - tau * (1.0 - decay)), 1e-13) << t;
      }
    }
    // Exact discretisation: one step of 2 s lands where 200 steps of 0.01 s did.
    PointRobot once({tau, 10.0, 1000.0, 0.0}, std::vector<double>(u.size(), 1.0), 1);
    once.setCommand(u);
    once.advance(2.0);
    for (std::size_t a = 0; a < u.size(); ++a) {
      EXPECT_NEAR(once.position()[a], robot.position()[a], 1e-13);
      EXPECT_NEAR(once.velocity()[a], robot.velocity()[a], 1e-14);
    }
    EXPECT_NEAR(robot.time(), 2.0, 1e-12);
  }
}

TEST(PointRobot, SpeedAndAccelerationLimitsHoldAndTheSaturatedPhaseIsExact) {
  const double tau = 0.1, vMax = 1.0, aMax = 2.0, dt = 0.001;
  PointRobot robot({tau, vMax, aMax, 0.0}, {0.0, 0.0}, 1);
  robot.setCommand({5.0, 5.0});
  const double e = 1.0 / std::sqrt(2.0);
  EXPECT_NEAR(norm(robot.command()), vMax, 1e-15);
  EXPECT_NEAR(robot.command()[0], e, 1e-15);
  // |u - v| > aMax tau = 0.2 until t1 = (1 - 0.2) / aMax = 0.4 s: constant acceleration aMax.
  std::vector<double> v = robot.velocity();
  for (int k = 1; k <= 1000; ++k) {
    robot.advance(dt);
    const double t = dt * k;
    std::vector<double> dv{robot.velocity()[0] - v[0], robot.velocity()[1] - v[1]};
    ASSERT_LE(norm(dv) / dt, aMax * (1.0 + 1e-9)) << t;
    ASSERT_LE(norm(robot.velocity()), vMax * (1.0 + 1e-15)) << t;
    v = robot.velocity();
    if (k == 300) {
      EXPECT_NEAR(v[0], aMax * t * e, 1e-12);
      EXPECT_NEAR(robot.position()[0], 0.5 * aMax * t * t * e, 1e-12);
    }
    if (k == 600) {
      // Then the lag: |u - v| = 0.2 e^{-(t - 0.4)/tau}.
      EXPECT_NEAR(vMax - norm(v), aMax * tau * std::exp(-(t - 0.4) / tau), 1e-12);
    }
  }
  // Reversing at full speed: still at most aMax.
  robot.setCommand({-vMax, 0.0});
  const double gap0 = std::hypot(-vMax - robot.velocity()[0], robot.velocity()[1]);
  for (int k = 0; k < 2000; ++k) {
    v = robot.velocity();
    robot.advance(dt);
    std::vector<double> dv{robot.velocity()[0] - v[0], robot.velocity()[1] - v[1]};
    ASSERT_LE(norm(dv) / dt, aMax * (1.0 + 1e-9));
    ASSERT_LE(norm(robot.velocity()), vMax * (1.0 + 1e-15));
  }
  // Saturated for (gap0 - aMax tau) / aMax, then the lag for the rest of the 2 s.
  const double t1 = (gap0 - aMax * tau) / aMax;
  EXPECT_NEAR(std::hypot(-vMax - robot.velocity()[0], robot.velocity()[1]),
              aMax * tau * std::exp(-(2.0 - t1) / tau), 1e-12);
}

TEST(PointRobot, WithoutLagOnlyTheAccelerationLimitShapesTheResponse) {
  PointRobot robot({0.0, 3.0, 4.0, 0.0}, {0.0, 0.0, 0.0}, 1);
  robot.setCommand({0.0, 2.0, 0.0});
  robot.advance(0.25);  // half way: v = aMax t
  EXPECT_NEAR(robot.velocity()[1], 1.0, 1e-15);
  robot.advance(0.5);   // reached u at t = 0.5 s, then cruises
  EXPECT_EQ(robot.velocity()[1], 2.0);
  EXPECT_NEAR(robot.position()[1], 0.5 * 4.0 * 0.25 + 2.0 * 0.25, 1e-14);
}

TEST(PointRobot, OdometryNoiseIsSeededGaussianWithTheGivenDeviation) {
  const double sigma = 0.01;
  const long n = 20000;
  PointRobot robot({0.1, 1.0, 1.0, sigma}, {1.0, -2.0}, 42), twin({0.1, 1.0, 1.0, sigma}, {1.0, -2.0}, 42);
  double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  long withinOne = 0;
  for (long m = 0; m < n; ++m) {
    const std::vector<double> z = robot.measuredPosition();
    ASSERT_EQ(z, twin.measuredPosition());
    const double x = (z[0] - 1.0) / sigma, y = (z[1] + 2.0) / sigma;
    sx += x, sy += y, sxx += x * x, syy += y * y, sxy += x * y;
    withinOne += std::abs(x) < 1.0;
  }
  const double N = static_cast<double>(n);
  // 5-sigma bounds of the sample statistics of N standard normals.
  EXPECT_NEAR(sx / N, 0.0, 5.0 / std::sqrt(N));
  EXPECT_NEAR(sy / N, 0.0, 5.0 / std::sqrt(N));
  EXPECT_NEAR(sxx / N, 1.0, 5.0 * std::sqrt(2.0 / N));
  EXPECT_NEAR(syy / N, 1.0, 5.0 * std::sqrt(2.0 / N));
  EXPECT_NEAR(sxy / N, 0.0, 5.0 / std::sqrt(N));
  const double p = 0.6826894921370859;  // P(|Z| < 1) = erf(1 / sqrt 2)
  EXPECT_NEAR(withinOne / N, p, 5.0 * std::sqrt(p * (1 - p) / N));
  EXPECT_EQ(robot.position(), (std::vector<double>{1.0, -2.0}));
  PointRobot exact({0.1, 1.0, 1.0, 0.0}, {1.0, -2.0}, 42);
  EXPECT_EQ(exact.measuredPosition(), exact.position());
}

std::string rejection(const PointRobotSettings& s, const std::vector<double>& q0 = {0.0, 0.0}) {
  try {
    PointRobot robot(s, q0, 0);
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "accepted";
}

TEST(PointRobot, BadSettingsAndInputsAreRejectedNamingTheParameter) {
  EXPECT_EQ(rejection({-0.1, 1.0, 1.0, 0.0}), "lag: must be finite and >= 0 s, got -0.1");
  EXPECT_EQ(rejection({0.1, 0.0, 1.0, 0.0}), "max_speed: must be finite and > 0 m/s, got 0");
  EXPECT_EQ(rejection({0.1, 1.0, HUGE_VAL, 0.0}), "max_acceleration: must be finite and > 0 m/s^2, got inf");
  EXPECT_EQ(rejection({0.1, 1.0, 1.0, -0.01}), "odometry_noise: must be finite and >= 0 m, got -0.01");
  EXPECT_EQ(rejection({}, {1.0}), "initial_position: expected 2 or 3 values, got 1");
  EXPECT_EQ(rejection({}, {1.0, 2.0, 3.0, 4.0}), "initial_position: expected 2 or 3 values, got 4");
  EXPECT_EQ(rejection({}, {1.0, std::nan("")}), "initial_position: must be finite, got nan");
  EXPECT_EQ(rejection({}), "accepted");
  PointRobot robot({}, {0.0, 0.0}, 0);
  robot.setCommand({0.5, 0.0});
  EXPECT_THROW(robot.setCommand({1.0}), InvalidInput);
  EXPECT_THROW(robot.setCommand({1.0, HUGE_VAL}), InvalidInput);
  EXPECT_EQ(robot.command(), (std::vector<double>{0.5, 0.0}));
  EXPECT_THROW(robot.advance(-0.01), InvalidInput);
  EXPECT_THROW(robot.advance(std::nan("")), InvalidInput);
}

}  // namespace
}  // namespace vf
