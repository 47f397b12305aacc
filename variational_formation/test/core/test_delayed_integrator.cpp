// The delayed and lossy model: D = 0 is the ordinary run bit for bit, an exactly solved
// two-agent delayed recurrence, the loss pattern, and predicted against simulated margins.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include <Eigen/Eigenvalues>

#include "test_support.hpp"
#include "variational_formation_core/studies/delay_campaign.hpp"
#include "variational_formation_core/studies/delay_margin.hpp"
#include "variational_formation_core/integrators/delayed_variational_integrator.hpp"
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/integrators/variational_integrator.hpp"

namespace vf {
namespace {

void expectBitIdentical(const std::string& name, StartMethod start) {
  const Scenario sc = loadScenario(test::configPath(name));
  const Formation f = makeFormation(sc);
  VariationalIntegrator plain(f, sc.initialPositions, sc.initialVelocities, sc.timeStep,
                              sc.dampingGain, start);
  DelayedVariationalIntegrator delayed(f, sc.initialPositions, sc.initialVelocities, sc.timeStep,
                                       sc.dampingGain, start, DelaySettings{});
  for (long k = 1; k <= sc.steps; ++k) {
    plain.step();
    delayed.step();
    // Exact equality of every coordinate of every agent at every step.
    ASSERT_TRUE((plain.positions().array() == delayed.positions().array()).all())
        << name << " step " << k;
  }
  EXPECT_EQ(plain.energy(), delayed.energy());
}

TEST(DelayedIntegrator, ZeroDelayIsTheOrdinaryRunBitForBit) {
  for (const char* name : {"hexagon", "tetrahedron", "grid24", "square", "free_particle"}) {
    expectBitIdentical(name, StartMethod::Variational);
  }
  expectBitIdentical("tetrahedron_paper", StartMethod::Paper);
}

TEST(DelayedIntegrator, LossZeroEqualsNoLossWhateverTheSeed) {
  const Scenario sc = loadScenario(test::configPath("hexagon"));
  const Formation f = makeFormation(sc);
  DelayedVariationalIntegrator a(f, sc.initialPositions, sc.initialVelocities, sc.timeStep,
                                 sc.dampingGain, StartMethod::Variational, {3, 0.0, 1});
  DelayedVariationalIntegrator b(f, sc.initialPositions, sc.initialVelocities, sc.timeStep,
                                 sc.dampingGain, StartMethod::Variational, {3, 0.0, 99});
  for (long k = 0; k < sc.steps; ++k) {
    a.step();
    b.step();
  }
  EXPECT_TRUE((a.positions().array() == b.positions().array()).all());
  EXPECT_EQ(a.lostStates(), 0);
  // And a delay changes the run (the test can fail).
  VariationalIntegrator plain(f, sc.initialPositions, sc.initialVelocities, sc.timeStep,
                              sc.dampingGain, StartMethod::Variational);
  for (long k = 0; k < sc.steps; ++k) plain.step();
  EXPECT_GT((plain.positions() - a.positions()).norm(), 1e-9);
}

TEST(DelayedIntegrator, LossIsSeededAndHasTheRequestedFraction) {
  const Scenario sc = loadScenario(test::configPath("grid24"));
  const Formation f = makeFormation(sc);
  const auto run = [&](std::uint64_t seed) {
    DelayedVariationalIntegrator vi(f, sc.initialPositions, sc.initialVelocities, sc.timeStep,
                                    sc.dampingGain, StartMethod::Variational, {2, 0.3, seed});
    for (long k = 0; k < sc.steps; ++k) vi.step();
    return std::make_pair(vi.positions(), std::make_pair(vi.lostStates(), vi.offeredStates()));
  };
  const auto a = run(7), b = run(7), c = run(8);
  EXPECT_TRUE((a.first.array() == b.first.array()).all());
  EXPECT_EQ(a.second, b.second);
  EXPECT_GT((a.first - c.first).norm(), 0.0);
  // 106 directed edges x 497 deliveries (steps D + 1 .. 499); binomial: |f - P| <= 5 sqrt(P (1 - P) / n).
  const double n = static_cast<double>(a.second.second);
  EXPECT_EQ(a.second.second, 2L * 53 * (sc.steps - 1 - 2));
  const double fraction = static_cast<double>(a.second.first) / n;
  EXPECT_LE(std::abs(fraction - 0.3), 5.0 * std::sqrt(0.3 * 0.7 / n));
}

TEST(DelayedIntegrator, BadSettingsAreRejected) {
  EXPECT_THROW(validateDelaySettings({-1, 0.0, 1}), InvalidInput);
  EXPECT_THROW(validateDelaySettings({0, 1.5, 1}), InvalidInput);
  EXPECT_THROW(validateDelaySettings({0, -0.1, 1}), InvalidInput);
  EXPECT_NO_THROW(validateDelaySettings({5, 1.0, 1}));
}

// Two agents on the x axis, one edge of length 1, desired x* = (0, -1). With a = (x_0 - x_1) - 1
// the linearised delayed recurrence is a^{k+1} = (1 + e) a^k - e a^{k-1} - 2c (a^k + a^{k-D})
// (a^m = a^0 for m < 0), solved here from the roots of its characteristic polynomial
// lambda^{D+1} - (1 + e - 2c) lambda^D + e lambda^{D-1} + 2c, independent of the integrator.
void expectTwoAgentExact(long D, double h, double kappa, bool growing) {
  Positions shape(2, 2);
  shape << 0.0, -1.0, 0.0, 0.0;
  const Formation f(2, shape, {{0, 1}});
  const double a0 = 1e-6;
  Positions q0 = shape;
  q0(0, 0) += 0.5 * a0;
  q0(0, 1) -= 0.5 * a0;
  DelayedVariationalIntegrator vi(f, q0, Positions::Zero(2, 2), h, kappa,
                                  StartMethod::Variational, {D, 0.0, 1});
  const VariationalCoefficients c(h, kappa);
  const double e = c.decay, g = c.gradientGain;
  // Characteristic polynomial coefficients, highest power first, then its roots.
  Eigen::VectorXd poly = Eigen::VectorXd::Zero(D + 2);
  poly(0) = 1.0;
  poly(1) = -(1.0 + e - 2.0 * g);
  poly(2) += e;
  poly(D + 1) += 2.0 * g;
  const int order = static_cast<int>(D + 1);
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(order, order);
  for (int j = 0; j < order; ++j) companion(0, j) = -poly(j + 1);
  for (int j = 1; j < order; ++j) companion(j, j - 1) = 1.0;
  const Eigen::VectorXcd roots = Eigen::EigenSolver<Eigen::MatrixXd>(companion, false).eigenvalues();
  // s_t = a^{t + 1 - D}: s_0..s_{D-1} = a^0 (history), s_D = a^1 (variational start:
  // a^1 = a^0 - (2h/(1 + e^{kappa h})) (h/2) 4 a^0).
  Eigen::VectorXcd init(order);
  for (int t = 0; t < order; ++t) init(t) = a0;
  init(order - 1) = a0 - c.startGain * 0.5 * h * 4.0 * a0;
  Eigen::MatrixXcd vandermonde(order, order);
  for (int t = 0; t < order; ++t)
    for (int m = 0; m < order; ++m) vandermonde(t, m) = std::pow(roots(m), t);
  const Eigen::VectorXcd coef = vandermonde.fullPivLu().solve(init);
  double worst = 0.0, scale = 0.0;
  for (long k = 1; k <= 400; ++k) {
    vi.step();
    const double simulated = (vi.positions()(0, 0) - vi.positions()(0, 1)) - 1.0;
    std::complex<double> exact = 0.0;
    for (int m = 0; m < order; ++m) exact += coef(m) * std::pow(roots(m), static_cast<double>(k + D - 1));
    worst = std::max(worst, std::abs(simulated - exact.real()));
    scale = std::max(scale, std::abs(exact.real()));
    EXPECT_EQ(vi.positions()(1, 0), 0.0);  // the motion stays on the line
    if (scale > 20.0 * a0) break;  // an unstable run leaves the linear regime
  }
  // Linear regime: the neglected terms are O(a^2), relative O(a) <= 2e-5.
  EXPECT_LE(worst, 1e-4 * scale) << "D " << D;
  EXPECT_EQ(scale > 20.0 * a0, growing) << "D " << D;
}

TEST(DelayedIntegrator, TwoAgentDelayedRecurrenceMatchesItsCharacteristicRoots) {
  expectTwoAgentExact(1, 0.1, 1.0, false);
  expectTwoAgentExact(3, 0.1, 1.0, false);
  expectTwoAgentExact(6, 0.3, 0.5, true);
}

TEST(DelayMargin, FixedModesAreExactlyTheRigidMotions) {
  for (const char* name : {"hexagon", "tetrahedron", "square"}) {
    const Scenario sc = loadScenario(test::configPath(name));
    const Formation f = makeFormation(sc);
    const int d = sc.dimension;
    for (long D : {0L, 1L, 5L}) {
      const DelaySpectrum s = delaySpectrum(f, sc.timeStep, sc.dampingGain, D);
      EXPECT_EQ(s.fixedModes, d * (d + 1) / 2) << name;
      EXPECT_EQ(s.eigenvaluesAtOne, d * (d + 1) / 2) << name << " D " << D;
      EXPECT_LT(s.excludedDistance, 1e-10);
    }
  }
}

TEST(DelayMargin, RootCountAgreesWithTheCompanionMatrix) {
  struct Case { const char* name; double kappa, h; };
  for (const Case& c : {Case{"hexagon", 4.0, 0.014}, Case{"tetrahedron", 1.0, 0.02},
                        Case{"square", 1.0, 0.02}}) {
    const Formation f = makeFormation(loadScenario(test::configPath(c.name)));
    for (long D = 0; D <= 14; ++D) {
      const bool stable = delaySpectrum(f, c.h, c.kappa, D).stable();
      EXPECT_EQ(unstableRootCount(f, c.h, c.kappa, D) == 0, stable) << c.name << " D " << D;
    }
  }
}

// The predicted margin against the simulated one (16 small perturbations, 5% of the shortest
// edge, 3000 steps, threshold 50%), checked at D* and D* + 1.
void expectMarginsAgree(const char* name, double kappa, double h, long expected) {
  const Scenario sc = loadScenario(test::configPath(name));
  const Formation f = makeFormation(sc);
  const DelayMargin predicted = predictDelayMargin(f, h, kappa, 30);
  EXPECT_FALSE(predicted.capped);
  EXPECT_TRUE(predicted.confirmed());
  // Regression pin (delay_margin on this branch; an independent numpy scan of the companion
  // matrix gave the same).
  EXPECT_EQ(predicted.margin, expected) << name;
  DelayCampaignSettings s;
  s.timeStep = h;
  s.dampingGain = kappa;
  s.steps = 3000;
  const DelayCampaign campaign(sc, s);
  const long D = predicted.margin;
  const auto cells = campaign.run({D, D + 1}, {0.0}, 2);
  EXPECT_GE(cells[0].congruentFraction(), 0.5) << name << " D* = " << D;
  EXPECT_LT(cells[1].congruentFraction(), 0.5) << name << " D* + 1";
  EXPECT_EQ(simulatedDelayMargin(cells), D);
}

TEST(DelayMargin, PredictedMarginAgreesWithSimulation) {
  expectMarginsAgree("hexagon", 4.0, 0.014, 3);
  expectMarginsAgree("tetrahedron", 1.0, 0.02, 3);
  expectMarginsAgree("square", 1.0, 0.02, 11);
}

TEST(DelayMargin, NoEdgesIsBadInput) {
  const Formation f = makeFormation(loadScenario(test::configPath("free_particle")));
  EXPECT_THROW(predictDelayMargin(f, 0.01, 1.0, 5), InvalidInput);
}

}  // namespace
}  // namespace vf
