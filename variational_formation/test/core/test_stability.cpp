// Linear stability boundary h w = 2 cosh(kappa h / 2) of the variational update.
#include <gtest/gtest.h>

#include <cmath>

#include "test_support.hpp"
#include "variational_formation_core/integrators/step_size_advice.hpp"
#include "variational_formation_core/integrators/variational_integrator.hpp"

namespace vf {
namespace {

// Two agents on a line (embedded in 2D) joined by one edge of length 1, started close to it:
// the stretching mode has w^2 = 2 * (2 d^2) = 4 (both endpoints move), the only nonzero one.
Formation pair() {
  Positions shape(2, 2);
  shape << 0.0, 1.0, 0.0, 0.0;
  return Formation(2, shape, {{0, 1}});
}

double finalSeparationError(double h, double kappa, long steps) {
  const Formation f = pair();
  Positions q0 = f.desiredShape();
  q0(0, 1) += 1e-6;  // linear regime
  VariationalIntegrator vi(f, q0, Positions::Zero(2, 2), h, kappa, StartMethod::Variational);
  for (long k = 0; k < steps; ++k) vi.step();
  const double error = std::abs((vi.positions().col(1) - vi.positions().col(0)).norm() - 1.0);
  return std::isfinite(error) ? error : HUGE_VAL;  // a blow-up to inf/nan counts as diverged
}

TEST(Stability, PairFrequencyFromHessian) {
  const Formation f = pair();
  EXPECT_NEAR(maxStiffnessFrequency(f, f.desiredShape()), 2.0, 1e-12);
}

TEST(Stability, BoundaryUndamped) {
  const double w = 2.0;
  const double limit = stableTimeStepLimit(w, 0.0);
  EXPECT_NEAR(limit, 1.0, 1e-12);  // Verlet: h w < 2
  EXPECT_LT(finalSeparationError(0.98 * limit, 0.0, 4000), 1e-5);
  EXPECT_GT(finalSeparationError(1.02 * limit, 0.0, 4000), 1e-2);
}

TEST(Stability, BoundaryDampedIsLargerThanVerlets) {
  const double w = 2.0, kappa = 0.8;
  const double limit = stableTimeStepLimit(w, kappa);
  EXPECT_GT(limit, 1.0);
  EXPECT_NEAR(limit * w, 2.0 * std::cosh(0.5 * kappa * limit), 1e-9);
  EXPECT_TRUE(isLinearlyStable(0.99 * limit, w, kappa));
  EXPECT_FALSE(isLinearlyStable(1.01 * limit, w, kappa));
  EXPECT_LT(finalSeparationError(0.98 * limit, kappa, 4000), 1e-6);
  EXPECT_GT(finalSeparationError(1.02 * limit, kappa, 4000), 1e-2);
}

TEST(Stability, StrongDampingHasNoLimit) {
  // min over h of 2 cosh(kappa h/2) - h w > 0 when w is small against kappa.
  EXPECT_TRUE(std::isinf(stableTimeStepLimit(0.5, 13.0)));
  EXPECT_TRUE(std::isinf(stableTimeStepLimit(0.0, 1.0)));
}

TEST(Stability, HugeStepsCompareWithoutOverflow) {
  // 2 cosh(kappa h / 2) and h w overflow here; the damped mode is still stable, the undamped not.
  EXPECT_TRUE(isLinearlyStable(1e308, 16.5, 13.0));
  EXPECT_FALSE(isLinearlyStable(1e308, 1e10, 0.0));
  EXPECT_FALSE(isLinearlyStable(1e300, 1e10, 1e-300));
  EXPECT_TRUE(isLinearlyStable(1e3, 0.0, 0.0));  // no stiffness: nothing to destabilise
}

TEST(Stability, AdviceWarnsAboveTheLimit) {
  const Formation f = pair();
  EXPECT_FALSE(adviseTimeStep(f, f.desiredShape(), 0.5, 0.0).exceeded);
  const StepSizeAdvice advice = adviseTimeStep(f, f.desiredShape(), 1.5, 0.0);
  EXPECT_TRUE(advice.exceeded);
  EXPECT_EQ(advice.message.rfind("time_step: h = 1.5 exceeds the linear stability limit 1 s", 0), 0u)
      << advice.message;
  // Named after the flag that set h, when one did.
  EXPECT_EQ(adviseTimeStep(f, f.desiredShape(), 1.5, 0.0, "--time-step").message.rfind("--time-step: h = 1.5", 0),
            0u);
}

}  // namespace
}  // namespace vf
