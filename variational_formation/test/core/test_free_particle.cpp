// The free particle (no edges): the exact discrete solution, v_{k+1} = e^{-kappa h} v_k.
#include <gtest/gtest.h>

#include <cmath>

#include "test_support.hpp"
#include "variational_formation_core/integrators/variational_integrator.hpp"

namespace vf {
namespace {

TEST(FreeParticle, VelocityDecaysByExactlyEToTheMinusKappaHPerStep) {
  const Scenario s = loadScenario(test::configPath("free_particle"));
  ASSERT_EQ(s.agentCount(), 1);
  ASSERT_TRUE(s.edges.empty());
  const Formation f = makeFormation(s);
  VariationalIntegrator vi(f, s.initialPositions, s.initialVelocities, s.timeStep, s.dampingGain,
                           StartMethod::Variational);
  const double a = std::exp(-s.dampingGain * s.timeStep);
  const double startGain = 2.0 * s.timeStep / (1.0 + std::exp(s.dampingGain * s.timeStep));
  const Eigen::Vector3d q0 = s.initialPositions.col(0), v0 = s.initialVelocities.col(0);
  // Exact discrete solution: q_k = q_0 + startGain v_0 (1 + a + ... + a^{k-1}).
  for (long k = 1; k <= s.steps; ++k) {
    const Eigen::Vector3d before = vi.velocities().col(0);
    vi.step();
    const Eigen::Vector3d v = vi.velocities().col(0);
    if (k >= 2) {
      // v is a difference quotient: its round-off is absolute, about eps |q| / h.
      const double roundOff = 8.0 * 2.2e-16 * vi.positions().norm() / s.timeStep;
      EXPECT_LT((v - a * before).norm(), 1e-12 * before.norm() + roundOff) << "step " << k;
    }
    const double geometric = (1.0 - std::pow(a, static_cast<double>(k))) / (1.0 - a);
    const Eigen::Vector3d exact = q0 + startGain * geometric * v0;
    EXPECT_LT((vi.positions().col(0) - exact).norm(), 1e-13 * exact.norm()) << "step " << k;
  }
}

TEST(FreeParticle, MatchesTheContinuousSolutionToSecondOrder) {
  // q(t) = q0 + v0 (1 - e^{-kappa t}) / kappa.
  const Scenario s = loadScenario(test::configPath("free_particle"));
  const Formation f = makeFormation(s);
  const auto errorAt1s = [&](double h) {
    VariationalIntegrator vi(f, s.initialPositions, s.initialVelocities, h, s.dampingGain,
                             StartMethod::Variational);
    const long steps = std::lround(1.0 / h);
    for (long k = 0; k < steps; ++k) vi.step();
    const Eigen::Vector3d exact = s.initialPositions.col(0) +
        s.initialVelocities.col(0) * (1.0 - std::exp(-s.dampingGain)) / s.dampingGain;
    return (vi.positions().col(0) - exact).norm();
  };
  EXPECT_NEAR(std::log2(errorAt1s(0.01) / errorAt1s(0.005)), 2.0, 0.1);
}

}  // namespace
}  // namespace vf
