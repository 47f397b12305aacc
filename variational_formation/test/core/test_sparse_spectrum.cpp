// The sparse checks that large formations use at load (core/sparse_spectrum.hpp) against the
// dense ones that small formations keep: the same matrices entry for entry, the same largest
// eigenvalue to 1e-10, the same rank, on formations just below the dense limit.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>

#include "variational_formation_core/model/sparse_spectrum.hpp"
#include "variational_formation_core/integrators/step_size_advice.hpp"

namespace vf {
namespace {

using Edges = std::vector<std::pair<int, int>>;

// A ring of n agents on a circle, each linked to the next `chords` agents (chords = 2: rigid).
Formation ring(int n, int chords, double radius = 3.0) {
  Positions q(2, n);
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    q.col(i) << radius * std::cos(a), radius * std::sin(a);
  }
  Edges e;
  for (int i = 0; i < n; ++i)
    for (int k = 1; k <= chords; ++k) e.emplace_back(i, (i + k) % n);
  return Formation(2, q, e);
}

// A triangulated rows x cols grid (rigid), in 2D or, lifted with a random height, in 3D.
Formation grid(int rows, int cols) {
  Positions q(2, rows * cols);
  Edges e;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const int i = r * cols + c;
      q.col(i) << c, r;
      if (c + 1 < cols) e.emplace_back(i, i + 1);
      if (r + 1 < rows) e.emplace_back(i, i + cols);
      if (c + 1 < cols && r + 1 < rows) e.emplace_back(i, i + cols + 1);
    }
  return Formation(2, q, e);
}

Positions perturbed(const Formation& f, double size, unsigned seed) {
  std::mt19937 generator(seed);
  std::normal_distribution<double> noise(0.0, size);
  Positions q = f.desiredShape();
  for (Eigen::Index i = 0; i < q.size(); ++i) q(i) += noise(generator);
  return q;
}

int denseRank(const Eigen::MatrixXd& m) {
  Eigen::BDCSVD<Eigen::MatrixXd> svd(m);
  const Eigen::VectorXd s = svd.singularValues();
  return static_cast<int>((s.array() > 1e-9 * std::max(1.0, s(0))).count());
}

TEST(SparseSpectrum, MatricesEqualTheDenseOnesEntryForEntry) {
  const Formation f = ring(40, 2);
  const Positions q = perturbed(f, 0.3, 1);
  EXPECT_EQ(Eigen::MatrixXd(sparseHessian(f, q)), f.hessian(q));
  EXPECT_EQ(Eigen::MatrixXd(sparseRigidityMatrix(f, q)), f.rigidityMatrix(q));
}

TEST(SparseSpectrum, LargestEigenvalueMatchesTheDenseSolver) {
  // Rings have double eigenvalues at the top; grids a cluster; perturbed starts neither.
  for (const Formation& f : {ring(120, 2), ring(90, 3), grid(9, 12)}) {
    for (unsigned seed : {0u, 2u, 3u}) {
      const Positions q = seed == 0 ? f.desiredShape() : perturbed(f, 0.4, seed);
      const double dense =
          Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(f.hessian(q), Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
      EXPECT_NEAR(largestEigenvalue(sparseHessian(f, q)), dense, 1e-10 * dense) << f.agentCount() << " seed " << seed;
    }
  }
}

TEST(SparseSpectrum, RankMatchesTheDenseSvd) {
  struct Case {
    Formation f;
    bool perturb;
  };
  const Case cases[] = {
      {ring(120, 2), false},  // rigid: rank 2n - 3
      {ring(120, 1), false},  // a cycle: flexible, rank n
      {ring(90, 3), true},
      {grid(9, 12), false},
      {grid(9, 12), true},
  };
  for (const Case& c : cases) {
    const Positions q = c.perturb ? perturbed(c.f, 0.2, 5) : c.f.desiredShape();
    EXPECT_EQ(sparseRank(sparseRigidityMatrix(c.f, q), 1e-9), denseRank(c.f.rigidityMatrix(q)))
        << c.f.agentCount() << " agents, " << c.f.edges().size() << " edges";
  }
  // Collinear positions: a path of agents on a line has rank n - 1 whatever its extra edges.
  Positions line(2, 100);
  Edges e;
  for (int i = 0; i < 100; ++i) {
    line.col(i) << i, 0.0;
    if (i + 1 < 100) e.emplace_back(i, i + 1);
    if (i + 2 < 100) e.emplace_back(i, i + 2);
  }
  const Formation path(2, line, e);
  EXPECT_EQ(sparseRank(sparseRigidityMatrix(path, line), 1e-9), 99);
  EXPECT_EQ(denseRank(path.rigidityMatrix(line)), 99);
}

TEST(SparseSpectrum, LargeFormationsTakeTheSparsePathWithTheSameAnswers) {
  // 210 agents in 2D (420 unknowns) is above kDenseSpectrumLimit: the public functions give
  // what the dense solvers give.
  const Formation f = ring(210, 2);
  const Positions q = perturbed(f, 0.3, 7);
  ASSERT_GT(2 * f.agentCount(), kDenseSpectrumLimit);
  const double dense =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(f.hessian(q), Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
  EXPECT_NEAR(maxStiffnessFrequency(f, q), std::sqrt(dense), 1e-10 * std::sqrt(dense));
  EXPECT_EQ(f.rigidityRank(q), denseRank(f.rigidityMatrix(q)));
  EXPECT_TRUE(f.isInfinitesimallyRigid(f.desiredShape()));
  EXPECT_FALSE(ring(210, 1).isInfinitesimallyRigid(ring(210, 1).desiredShape()));
}

}  // namespace
}  // namespace vf
