// Discrete Noether theorem: momenta follow e^{-kappa t_k} X_0 (conserved when kappa = 0).
#include <gtest/gtest.h>

#include <iostream>

#include "test_support.hpp"
#include "variational_formation_core/model/metrics.hpp"
#include "variational_formation_core/integrators/variational_integrator.hpp"

namespace vf {
namespace {

struct Residuals {
  double linear = 0.0;
  double angular = 0.0;
};

Residuals noetherResiduals(double kappa, long steps, double h, bool zeroMeanVelocity = false) {
  const Formation f = test::tetrahedron();
  Positions q0 = f.desiredShape();
  q0.col(1) += Eigen::Vector3d(0.4, -0.3, 0.2);
  Velocities v0(3, 4);
  v0 << 0.8, -0.3, 0.1, 0.5, -0.6, 0.9, 0.2, -0.4, 0.3, 0.7, -0.5, 0.6;
  if (zeroMeanVelocity) v0.colwise() -= v0.rowwise().mean();
  VariationalIntegrator vi(f, q0, v0, h, kappa, StartMethod::Variational);
  const VariationalCoefficients c(h, kappa);
  const Vector3 p0 = linearMomentum(vi.momenta());
  const Vector3 a0 = angularMomentum(vi.positions(), vi.momenta());
  Residuals r;
  for (long k = 1; k <= steps; ++k) {
    vi.step();
    const Momenta p = vi.momenta();
    // With a zero total momentum, the residual is absolute (relative to 1).
    r.linear = std::max(r.linear, noetherResidual(linearMomentum(p), noetherPrediction(p0, c, k),
                                                  zeroMeanVelocity ? Vector3(1, 0, 0) : p0));
    r.angular = std::max(r.angular, noetherResidual(angularMomentum(vi.positions(), p),
                                                    noetherPrediction(a0, c, k), a0));
  }
  std::cout << "kappa " << kappa << ", " << steps << " steps: max relative residual linear "
            << r.linear << ", angular " << r.angular << '\n';
  return r;
}

TEST(DiscreteNoether, MomentaDecayAsPredictedWithDamping) {
  const Residuals r = noetherResiduals(1.0, 20000, 0.005);  // t up to 100 s
  EXPECT_LE(r.linear, 1e-10);
  EXPECT_LE(r.angular, 1e-10);
}

TEST(DiscreteNoether, UndampedDriftingFormationConservesMomentumToRoundOff) {
  // P_0 != 0: over 10 s the formation drifts 8 m; residuals stay at round-off level.
  const Residuals r = noetherResiduals(0.0, 2000, 0.005);
  EXPECT_LE(r.linear, 1e-10);
  EXPECT_LE(r.angular, 1e-10);
}

TEST(DiscreteNoether, StrongDampingLongRunNeverOverflows) {
  // kappa t reaches 13 * 100 = 1300 > 709: e^{kappa t} would overflow; the prediction does not.
  const Residuals r = noetherResiduals(13.0, 20000, 0.005);
  EXPECT_LE(r.linear, 1e-10);
  EXPECT_LE(r.angular, 1e-10);
}

TEST(DiscreteNoether, MomentaConservedWithoutDamping) {
  // Undamped, a nonzero P_0 carries the formation 80 m away in 100 s, and the round-off of
  // q x p then grows with |q|: this case therefore holds the centroid still (P_0 = 0).
  const Residuals r = noetherResiduals(0.0, 20000, 0.005, /*zeroMeanVelocity=*/true);
  EXPECT_LE(r.linear, 1e-10);
  EXPECT_LE(r.angular, 1e-10);
}

TEST(Metrics, PerAgentEnergySumsToDiscreteEnergy) {
  const Formation f = test::tetrahedron();
  Positions q0 = f.desiredShape(), q1 = f.desiredShape();
  q0.col(0) += Eigen::Vector3d(0.2, 0.1, 0.0);
  q1.col(3) += Eigen::Vector3d(0.0, -0.1, 0.3);
  const double total = discreteEnergy(f, 0.01, q0, q1);
  EXPECT_NEAR(agentDiscreteEnergy(f, 0.01, q0, q1).sum(), total, 1e-12 * total);
  const Positions v = (q1 - q0) / 0.01;
  EXPECT_NEAR(agentContinuousEnergy(f, q1, v).sum(), continuousEnergy(f, q1, v), 1e-12 * total);
}

TEST(Metrics, AngularMomentumIn2DIsAScalarAboutZ) {
  Positions q(2, 1), p(2, 1);
  q << 1.0, 0.0;
  p << 0.0, 2.0;
  const Vector3 a = angularMomentum(q, p);
  EXPECT_DOUBLE_EQ(a.z(), 2.0);
  EXPECT_DOUBLE_EQ(a.x(), 0.0);
  EXPECT_DOUBLE_EQ(linearMomentum(p).y(), 2.0);
}

}  // namespace
}  // namespace vf
