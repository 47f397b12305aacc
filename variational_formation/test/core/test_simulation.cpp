// runScenario on the shipped scenarios: each ends as its file says it does.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <utility>

#include "test_support.hpp"
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/integrators/step_metrics.hpp"

namespace vf {
namespace {

/// Congruence at the last step and the first step of the final congruent stretch (-1 if none).
struct Outcome {
  long observed = 0;
  bool congruent = false;
  long congruentSince = -1;
  bool finite = true;
};

Outcome run(const Scenario& s, const std::function<void(const Integrator&)>& extra = {}) {
  Outcome o;
  runScenario(s, Method::Variational, StartMethod::Variational, [&](const Integrator& integ) {
    ++o.observed;
    o.finite = o.finite && integ.positions().allFinite();
    o.congruent = integ.formation().isCongruent(integ.positions(), integ.velocities());
    if (!o.congruent) o.congruentSince = -1;
    else if (o.congruentSince < 0) o.congruentSince = integ.stepIndex();
    if (extra) extra(integ);
  });
  return o;
}

TEST(Simulation, ConvergingScenariosEndCongruent) {
  for (const char* name : {"tetrahedron", "square", "hexagon", "grid24"}) {
    const Scenario s = loadScenario(test::configPath(name));
    const Outcome o = run(s);
    EXPECT_EQ(o.observed, s.steps + 1) << name;
    EXPECT_TRUE(o.finite) << name;
    EXPECT_TRUE(o.congruent) << name;
    // Settled with a margin: congruent for at least the last tenth of the run.
    EXPECT_GE(o.congruentSince, 0) << name;
    EXPECT_LE(o.congruentSince, s.steps - s.steps / 10) << name;
  }
}

/// Time [s] from which an RK4 run at a tenth of the scenario's step stays congruent (-1 if
/// it never does): a second method, independent of the variational scheme.
double rk4CongruentSince(const Scenario& s) {
  const Formation f = makeFormation(s);
  const double h = s.timeStep / 10.0;
  auto rk4 = makeIntegrator(Method::RungeKutta4, f, s.initialPositions, s.initialVelocities, h, s.dampingGain);
  double since = -1.0;
  for (long k = 0; k <= 10 * s.steps; ++k) {
    if (k > 0) rk4->step();
    if (!f.isCongruent(rk4->positions(), rk4->velocities())) since = -1.0;
    else if (since < 0.0) since = rk4->time();
  }
  return since;
}

TEST(Simulation, CongruenceOnsetAgreesWithRungeKutta4AtATenthOfTheStep) {
  // The steps below are regression pins: each is the code's own output (`simulate`, quoted in
  // the scenario file's comment), not an independent fact. The independent check is RK4: the
  // variational run must become congruent at the same time to within 2.5 of its steps (its
  // speeds are difference quotients, half a step behind, and the thresholds are crossed slowly).
  const std::pair<const char*, long> pinned[] = {{"tetrahedron", 847}, {"square", 905}, {"hexagon", 210},
                                                 {"grid24", 320}};
  for (const auto& [name, pin] : pinned) {
    const Scenario s = loadScenario(test::configPath(name));
    const Outcome o = run(s);
    const double reference = rk4CongruentSince(s);
    ASSERT_GE(reference, 0.0) << name;
    std::cout << name << ": variational from step " << o.congruentSince << " (t = "
              << o.congruentSince * s.timeStep << " s), RK4 at h/10 from t = " << reference << " s\n";
    EXPECT_NEAR(o.congruentSince * s.timeStep, reference, 2.5 * s.timeStep) << name;
    EXPECT_EQ(o.congruentSince, pin) << name << " (regression pin)";
  }
}

TEST(Simulation, PaperTetrahedronStaysInItsPlaneAndNeverFormsTheTetrahedron) {
  // The paper's start lies in the plane 3x - y = 3; the flow never leaves it, and a planar
  // configuration cannot be congruent with a regular tetrahedron.
  const Scenario s = loadScenario(test::configPath("tetrahedron_paper"));
  double worst = 0.0;
  const Outcome o = run(s, [&](const Integrator& integ) {
    const Positions& q = integ.positions();
    for (Eigen::Index i = 0; i < q.cols(); ++i) {
      worst = std::max(worst, std::abs(3.0 * q(0, i) - q(1, i) - 3.0));
    }
  });
  EXPECT_TRUE(o.finite);
  EXPECT_LT(worst, 1e-12);
  EXPECT_FALSE(o.congruent);
  EXPECT_EQ(o.congruentSince, -1);
}

TEST(Simulation, UnboundedScenarioIsRejected) {
  Scenario s = loadScenario(test::configPath("hexagon"));
  s.steps = 0;
  EXPECT_THROW(run(s), InvalidInput);
}

}  // namespace
}  // namespace vf
