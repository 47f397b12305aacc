// runScenario on the shipped scenarios: each ends as its file says it does.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "test_support.hpp"
#include "variational_formation/core/error.hpp"
#include "variational_formation/core/simulation.hpp"

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
