// Formation: derivatives against finite differences, rigidity on known graphs, congruence.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "test_support.hpp"
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/integrators/integrator.hpp"

namespace vf {
namespace {

Positions randomPositions(int d, int n, unsigned seed, double scale = 2.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-scale, scale);
  Positions q(d, n);
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < d; ++a) q(a, i) = u(rng);
  return q;
}

TEST(Formation, GradientMatchesCentralDifferences) {
  const Formation f = test::tetrahedron();
  const Positions q = randomPositions(3, 4, 1);
  Gradients g;
  f.gradient(q, g);
  const double eps = 1e-6;
  for (int i = 0; i < 4; ++i) {
    for (int a = 0; a < 3; ++a) {
      Positions qp = q, qm = q;
      qp(a, i) += eps;
      qm(a, i) -= eps;
      const double fd = (f.potential(qp) - f.potential(qm)) / (2 * eps);
      EXPECT_NEAR(g(a, i), fd, 1e-6 * std::max(1.0, std::abs(fd)));
    }
  }
}

TEST(Formation, HessianMatchesDifferencesOfGradient) {
  const Formation f = test::triangle();
  const Positions q = randomPositions(2, 3, 2);
  const Eigen::MatrixXd h = f.hessian(q);
  EXPECT_LT((h - h.transpose()).norm(), 1e-12);
  const double eps = 1e-6;
  for (int j = 0; j < 3; ++j) {
    for (int b = 0; b < 2; ++b) {
      Positions qp = q, qm = q;
      Gradients gp, gm;
      qp(b, j) += eps;
      qm(b, j) -= eps;
      f.gradient(qp, gp);
      f.gradient(qm, gm);
      const Gradients column = (gp - gm) / (2 * eps);
      for (int i = 0; i < 3; ++i)
        for (int a = 0; a < 2; ++a)
          EXPECT_NEAR(h(2 * i + a, 2 * j + b), column(a, i), 1e-5 * std::max(1.0, h.norm()));
    }
  }
}

TEST(Formation, AgentPotentialsSumToPotentialAndVanishAtDesiredShape) {
  const Formation f = test::tetrahedron();
  const Positions q = randomPositions(3, 4, 3);
  double sum = 0.0;
  for (int i = 0; i < 4; ++i) sum += f.agentPotential(i, q);
  EXPECT_NEAR(sum, f.potential(q), 1e-12 * f.potential(q));
  EXPECT_LT(f.potential(f.desiredShape()), 1e-28);
  Gradients g;
  f.gradient(f.desiredShape(), g);
  EXPECT_LT(g.norm(), 1e-14);
}

TEST(Formation, GradientIsTranslationAndRotationInvariant) {
  // SE(d) invariance of V is what the Noether laws rest on: the gradients sum to zero.
  const Formation f = test::tetrahedron();
  const Positions q = randomPositions(3, 4, 4);
  Gradients g;
  f.gradient(q, g);
  EXPECT_LT(g.rowwise().sum().norm(), 1e-12 * g.norm());
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();
  for (int i = 0; i < 4; ++i) torque += Eigen::Vector3d(q.col(i)).cross(Eigen::Vector3d(g.col(i)));
  EXPECT_LT(torque.norm(), 1e-12 * g.norm() * q.norm());
}

Formation square(bool withDiagonal) {
  Positions shape(2, 4);
  shape << 0, 1, 1, 0, 0, 0, 1, 1;
  std::vector<std::pair<int, int>> edges{{0, 1}, {1, 2}, {2, 3}, {3, 0}};
  if (withDiagonal) edges.emplace_back(0, 2);
  return Formation(2, shape, edges);
}

TEST(Rigidity, KnownGraphs) {
  const Formation tri = test::triangle();
  EXPECT_TRUE(tri.isInfinitesimallyRigid(tri.desiredShape()));
  EXPECT_TRUE(tri.isMinimallyRigid(tri.desiredShape()));

  const Formation open = square(false);
  EXPECT_EQ(open.rigidityRank(open.desiredShape()), 4);
  EXPECT_FALSE(open.isInfinitesimallyRigid(open.desiredShape()));

  const Formation braced = square(true);
  EXPECT_TRUE(braced.isInfinitesimallyRigid(braced.desiredShape()));
  EXPECT_TRUE(braced.isMinimallyRigid(braced.desiredShape()));

  const Formation k4 = test::tetrahedron();
  EXPECT_EQ(k4.rigidityRank(k4.desiredShape()), 6);
  EXPECT_TRUE(k4.isMinimallyRigid(k4.desiredShape()));
  // A flat K4 (coplanar points) is not infinitesimally rigid in 3D.
  Positions flat(3, 4);
  flat << 0, 1, 1, 0, 0, 0, 1, 1, 0, 0, 0, 0;
  EXPECT_FALSE(k4.isInfinitesimallyRigid(flat));
}

TEST(Rigidity, HexagonScenarioIsMinimallyRigid) {
  const Scenario s = loadScenario(test::configPath("hexagon"));
  const Formation f = makeFormation(s);
  EXPECT_EQ(f.edges().size(), 9u);
  EXPECT_TRUE(f.isMinimallyRigid(f.desiredShape()));
  // Dropping any edge breaks rigidity.
  for (std::size_t drop = 0; drop < s.edges.size(); ++drop) {
    auto edges = s.edges;
    edges.erase(edges.begin() + static_cast<long>(drop));
    const Formation g(2, s.desiredPositions, edges);
    EXPECT_FALSE(g.isInfinitesimallyRigid(g.desiredShape())) << "without edge " << drop;
  }
}

TEST(Rigidity, RigidityMatrixRowsAreHalfTheEdgeLengthJacobian) {
  const Formation f = test::tetrahedron();
  const Positions q = randomPositions(3, 4, 5);
  const Eigen::MatrixXd r = f.rigidityMatrix(q);
  const double eps = 1e-6;
  for (int c = 0; c < 12; ++c) {
    Positions qp = q, qm = q;
    qp(c % 3, c / 3) += eps;
    qm(c % 3, c / 3) -= eps;
    for (std::size_t e = 0; e < f.edges().size(); ++e) {
      const auto& edge = f.edges()[e];
      const auto len2 = [&](const Positions& x) { return (x.col(edge.tail) - x.col(edge.head)).squaredNorm(); };
      EXPECT_NEAR(r(static_cast<long>(e), c), 0.5 * (len2(qp) - len2(qm)) / (2 * eps), 1e-7);
    }
  }
}

TEST(Congruence, RigidMotionsAndReflectionsAreCongruent) {
  const Formation f = test::tetrahedron();
  const Eigen::Matrix3d rot =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Positions moved = rot * f.desiredShape();
  moved.colwise() += Eigen::Vector3d(5, -2, 1);
  const Velocities still = Velocities::Zero(3, 4);
  EXPECT_TRUE(f.isCongruent(moved, still));
  Positions mirrored = f.desiredShape();
  mirrored.row(2) *= -1.0;
  EXPECT_TRUE(f.isCongruent(mirrored, still));
}

// The tracker answers exactly as isCongruent along a converging run of the hexagon (kappa 2,
// 4000 steps, congruent from step ~800 on), and the full pair test runs on few of its steps.
TEST(Congruence, TrackerEqualsTheFullTestAlongARun) {
  const Scenario sc = loadScenario(test::configPath("hexagon"));
  const Formation f = makeFormation(sc);
  const auto integ = makeIntegrator(Method::Variational, f, sc.initialPositions, sc.initialVelocities, sc.timeStep,
                                    sc.dampingGain);
  CongruenceTracker tracker(0.01, 0.1);
  long congruent = 0;
  const long steps = 4000;
  for (long k = 0; k <= steps; ++k) {
    if (k > 0) integ->step();
    const bool full = f.isCongruent(integ->positions(), integ->velocities());
    ASSERT_EQ(tracker.check(f, integ->positions(), integ->velocities()), full) << "step " << k;
    congruent += full ? 1 : 0;
  }
  ASSERT_GT(congruent, steps / 2);
  // Every congruent step would cost a full test without the anchor; the run settles, so the
  // displacements stay far below the slack and a few percent of them do.
  EXPECT_LT(tracker.fullTests(), congruent / 20)
      << tracker.fullTests() << " full tests, " << congruent << " congruent steps";
}

// A random walk of a tetrahedron's positions around the tolerance boundary (every third step up
// to 0.2% of a side, the others 1000 times smaller, pulled back to the desired shape): the
// tracker agrees with isCongruent at every step, on both outcomes, and skips the full test on
// some congruent steps.
TEST(Congruence, TrackerEqualsTheFullTestOnARandomWalk) {
  const Formation f = test::tetrahedron();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> step(-0.004, 0.004);
  CongruenceTracker tracker(0.01, 0.1);
  Positions q = f.desiredShape();
  const Velocities still = Velocities::Zero(3, 4);
  long yes = 0, no = 0;
  for (int k = 0; k < 20000; ++k) {
    for (int i = 0; i < q.rows(); ++i) {
      for (int j = 0; j < q.cols(); ++j) q(i, j) += step(rng) * (k % 3 == 0 ? 1.0 : 1e-3) - 0.01 * (q(i, j) - f.desiredShape()(i, j));
    }
    const bool full = f.isCongruent(q, still);
    ASSERT_EQ(tracker.check(f, q, still), full) << "step " << k;
    (full ? yes : no)++;
  }
  EXPECT_GT(yes, 1000);
  EXPECT_GT(no, 1000);
  EXPECT_GT(20000 - tracker.fullTests(), 1000) << tracker.fullTests() << " full tests";  // steps answered by the anchor
}

TEST(Congruence, DistanceAndSpeedThresholds) {
  const Formation f = test::triangle();
  const Velocities still = Velocities::Zero(2, 3);
  Positions stretched = f.desiredShape();
  stretched(0, 1) = 1.02;  // pair (0,1) 2% long
  EXPECT_FALSE(f.isCongruent(stretched, still));
  stretched(0, 1) = 1.005;  // 0.5% long, and the other pairs change by less
  EXPECT_TRUE(f.isCongruent(stretched, still));
  Velocities moving = still;
  moving(1, 2) = 0.11;
  EXPECT_FALSE(f.isCongruent(f.desiredShape(), moving));
  moving(1, 2) = 0.09;
  EXPECT_TRUE(f.isCongruent(f.desiredShape(), moving));
  // Non-edges count too: a square without its diagonal sheared into a rhombus keeps its edge
  // lengths but is not congruent.
  const Formation open = square(false);
  Positions rhombus(2, 4);
  rhombus << 0, 1, 1.5, 0.5, 0, 0, 0.8660254037844386, 0.8660254037844386;
  EXPECT_LT(open.maxDistanceError(rhombus), 1e-12);
  EXPECT_FALSE(open.isCongruent(rhombus, Velocities::Zero(2, 4)));
}

TEST(Formation, DistanceErrorsPerEdge) {
  const Formation f = test::triangle();
  Positions q = f.desiredShape();
  q(0, 1) = 1.5;
  const Eigen::VectorXd e = f.distanceErrors(q);
  ASSERT_EQ(e.size(), 3);
  EXPECT_NEAR(e(0), 0.5, 1e-15);
  EXPECT_NEAR(f.maxDistanceError(q), 0.5, 1e-15);
}

TEST(Formation, RejectsBadEdgesAndDimensions) {
  Positions shape = Positions::Zero(2, 3);
  EXPECT_THROW(Formation(4, Positions::Zero(4, 3), {}), InvalidInput);
  EXPECT_THROW(Formation(2, shape, {{0, 3}}), InvalidInput);
  EXPECT_THROW(Formation(2, shape, {{1, 1}}), InvalidInput);
  EXPECT_THROW(Formation(2, shape, {{0, 1}, {1, 0}}), InvalidInput);
  EXPECT_THROW(Formation(3, shape, {}), InvalidInput);
}

}  // namespace
}  // namespace vf
