// Integrators: convergence order by halving h, energy behaviour, Euler's instability, RK4.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "test_support.hpp"
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/metrics.hpp"
#include "variational_formation_core/integrators/variational_integrator.hpp"

namespace vf {
namespace {

struct Problem {
  Formation formation = test::tetrahedron();
  Positions q0;
  Velocities v0;
  Problem() {
    q0 = formation.desiredShape();
    q0.col(0) += Eigen::Vector3d(0.3, -0.2, 0.1);
    q0.col(2) += Eigen::Vector3d(-0.1, 0.25, 0.2);
    v0 = Velocities::Zero(3, 4);
    v0.col(1) = Eigen::Vector3d(0.5, 0.2, -0.4);
    v0.col(3) = Eigen::Vector3d(-0.3, 0.6, 0.1);
  }
};

Positions runTo(Method method, const Problem& p, double h, double kappa, double T,
                StartMethod start = StartMethod::Variational) {
  auto integ = makeIntegrator(method, p.formation, p.q0, p.v0, h, kappa, start);
  const long steps = std::lround(T / h);
  for (long k = 0; k < steps; ++k) integ->step();
  return integ->positions();
}

// Errors at T = 1 s for h, h/2, h/4, h/8 against RK4 at h = 1e-4; returns the last order.
double measuredOrder(StartMethod start, double kappa) {
  const Problem p;
  const double T = 1.0;
  const Positions reference = runTo(Method::RungeKutta4, p, 1e-4, kappa, T);
  double previous = 0.0, order = 0.0;
  for (double h : {0.01, 0.005, 0.0025, 0.00125}) {
    const double error = (runTo(Method::Variational, p, h, kappa, T, start) - reference).norm();
    if (previous > 0.0) {
      order = std::log2(previous / error);
      std::cout << "  h = " << h << ": error " << error << ", order " << order << '\n';
    }
    previous = error;
  }
  return order;
}

TEST(ConvergenceOrder, VariationalStartIsSecondOrder) {
  for (double kappa : {0.0, 2.0, 13.0}) {
    std::cout << "variational start, kappa = " << kappa << '\n';
    EXPECT_NEAR(measuredOrder(StartMethod::Variational, kappa), 2.0, 0.1) << "kappa " << kappa;
  }
}

TEST(ConvergenceOrder, PaperStartIsFirstOrder) {
  for (double kappa : {2.0, 13.0}) {
    std::cout << "paper start, kappa = " << kappa << '\n';
    EXPECT_NEAR(measuredOrder(StartMethod::Paper, kappa), 1.0, 0.1) << "kappa " << kappa;
  }
}

TEST(ConvergenceOrder, RungeKutta4IsFourthOrder) {
  const Problem p;
  const Positions reference = runTo(Method::RungeKutta4, p, 1e-4, 2.0, 1.0);
  const double e1 = (runTo(Method::RungeKutta4, p, 0.02, 2.0, 1.0) - reference).norm();
  const double e2 = (runTo(Method::RungeKutta4, p, 0.01, 2.0, 1.0) - reference).norm();
  EXPECT_NEAR(std::log2(e1 / e2), 4.0, 0.3);
}

TEST(Energy, DiscreteEnergyDecaysWithDamping) {
  const Problem p;
  VariationalIntegrator vi(p.formation, p.q0, p.v0, 0.005, 3.0, StartMethod::Variational);
  const double e0 = vi.energy();
  vi.step();
  double previous = vi.energy();
  int increases = 0;
  for (int k = 0; k < 2000; ++k) {
    vi.step();
    if (vi.energy() > previous * (1.0 + 1e-12)) ++increases;
    previous = vi.energy();
  }
  EXPECT_EQ(increases, 0);
  EXPECT_LT(previous, 1e-6 * e0);
}

TEST(Energy, BoundedWithoutDriftOverHundredThousandStepsWhenUndamped) {
  const Problem p;
  VariationalIntegrator vi(p.formation, p.q0, p.v0, 0.01, 0.0, StartMethod::Variational);
  vi.step();
  const double e1 = vi.energy();
  const long steps = 100000;
  double firstTenth = 0.0, lastTenth = 0.0, sumFirst = 0.0, sumLast = 0.0;
  for (long k = 1; k <= steps; ++k) {
    vi.step();
    const double dev = std::abs(vi.energy() - e1);
    if (k <= steps / 10) {
      firstTenth = std::max(firstTenth, dev);
      sumFirst += vi.energy();
    }
    if (k > steps - steps / 10) {
      lastTenth = std::max(lastTenth, dev);
      sumLast += vi.energy();
    }
  }
  std::cout << "E_1 = " << e1 << ", max |E - E_1| first tenth " << firstTenth << ", last tenth "
            << lastTenth << '\n';
  EXPECT_LT(lastTenth, 1e-2 * e1);  // bounded: O(h^2) oscillation
  EXPECT_LT(lastTenth, 2.0 * firstTenth + 1e-12);  // no secular growth
  // The mean over the last tenth equals the mean over the first to well within the oscillation.
  EXPECT_NEAR(sumLast / (steps / 10), sumFirst / (steps / 10), 0.5 * firstTenth);
}

TEST(Energy, ExplicitEulerGainsEnergyWhenUndamped) {
  const Problem p;
  auto euler = makeIntegrator(Method::ExplicitEuler, p.formation, p.q0, p.v0, 0.01, 0.0);
  const double e0 = euler->energy();
  for (int k = 0; k < 2000; ++k) euler->step();
  EXPECT_GT(euler->energy(), 1.05 * e0);
}

TEST(HamiltonianFlow, ReproducesTheIntegratorsMomentaAndPositions) {
  const Problem p;
  const double h = 0.01, kappa = 2.0;
  VariationalIntegrator vi(p.formation, p.q0, p.v0, h, kappa, StartMethod::Variational);
  const VariationalCoefficients c(h, kappa);
  Positions q = p.q0, qn;
  Momenta pk = p.v0, pn;  // p_0 = v_0: the variational start
  for (int k = 0; k < 300; ++k) {
    discreteHamiltonianFlow(p.formation, c, q, pk, qn, pn);
    vi.step();
    ASSERT_LT((qn - vi.positions()).norm(), 1e-12 * (1.0 + qn.norm())) << "step " << k;
    ASSERT_LT((pn - vi.momenta()).norm(), 1e-10 * (1.0 + pn.norm())) << "step " << k;
    q = qn;
    pk = pn;
  }
}

TEST(HamiltonianFlow, MomentumMatchingHoldsAlongTrajectory) {
  // The update is exactly p-_{k} = p+_{k} (doc/maths.md §4).
  const Problem p;
  const double h = 0.01, kappa = 5.0;
  VariationalIntegrator vi(p.formation, p.q0, p.v0, h, kappa, StartMethod::Variational);
  const VariationalCoefficients c(h, kappa);
  vi.step();
  for (int k = 0; k < 200; ++k) {
    const Positions qPrev = vi.previousPositions(), q = vi.positions();
    vi.step();
    const Momenta plus = discreteMomentumPlus(p.formation, c, qPrev, q);
    const Momenta minus = discreteMomentumMinus(p.formation, c, q, vi.positions());
    ASSERT_LT((plus - minus).norm(), 1e-11 * (1.0 + plus.norm())) << "step " << k;
  }
}

TEST(Integrator, RejectsBadArguments) {
  const Problem p;
  EXPECT_THROW(makeIntegrator(Method::Variational, p.formation, p.q0, p.v0, 0.0, 1.0), InvalidInput);
  EXPECT_THROW(makeIntegrator(Method::Variational, p.formation, p.q0, p.v0, 0.01, -1.0), InvalidInput);
  EXPECT_THROW(makeIntegrator(Method::Variational, p.formation, Positions::Zero(2, 4), p.v0, 0.01, 1.0),
               InvalidInput);
  Positions bad = p.q0;
  bad(0, 0) = std::nan("");
  EXPECT_THROW(makeIntegrator(Method::RungeKutta4, p.formation, bad, p.v0, 0.01, 1.0), InvalidInput);
  EXPECT_THROW(parseMethod("verlet"), InvalidInput);
  EXPECT_THROW(parseStartMethod("magic"), InvalidInput);
  EXPECT_EQ(parseMethod("rk4"), Method::RungeKutta4);
}

}  // namespace
}  // namespace vf
