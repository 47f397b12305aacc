#include "variational_formation_core/model/rigidity.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <random>

#include "variational_formation_core/common/standard_normal.hpp"

namespace vf {

namespace {

// Relative tolerances. Generic realizations keep their smallest nonzero singular values many
// orders above these; the zero ones are round-off, about 1e-15 relative.
constexpr double kRankTolerance = 1e-9;
constexpr double kStressTolerance = 1e-8;

int countAbove(const Eigen::VectorXd& values, double relative) {
  const double largest = values.size() ? values.cwiseAbs().maxCoeff() : 0.0;
  if (!(largest > 0.0)) return 0;
  return static_cast<int>((values.cwiseAbs().array() > relative * largest).count());
}

RigidityReport classifyRealization(const Formation& graph, std::uint64_t seed) {
  const int d = graph.dimension(), n = graph.agentCount();
  const int m = static_cast<int>(graph.edges().size());
  RigidityReport r;
  r.dimension = d;
  r.agents = n;
  r.edges = m;
  const int pairs = n * (n - 1) / 2;
  const bool simplex = n <= d + 1;
  r.neededRank = simplex ? pairs : rigidEdgeCount(d, n);

  std::mt19937_64 engine(seed);
  StandardNormal normal;
  Positions q(d, n);
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < d; ++a) q(a, i) = normal(engine);
  // The generic test runs on the same graph placed at q.
  std::vector<std::pair<int, int>> edges;
  for (const Edge& e : graph.edges()) edges.emplace_back(e.tail, e.head);
  const Formation generic(d, q, edges);

  Eigen::MatrixXd stressBasis(m, 0);
  if (m > 0) {
    Eigen::BDCSVD<Eigen::MatrixXd> svd(generic.rigidityMatrix(q), Eigen::ComputeFullU);
    r.rank = countAbove(svd.singularValues(), kRankTolerance);
    // The left null space of R: the equilibrium stresses w with R^T w = 0.
    stressBasis = svd.matrixU().rightCols(m - r.rank);
  }
  r.stresses = m - r.rank;
  r.rigid = simplex ? m == pairs : r.rank == r.neededRank;
  r.minimallyRigid = r.rigid && m == r.neededRank;
  // Edge e can go without losing rank iff row e of R is a combination of the others, iff some
  // stress is nonzero on e: row e of the stress basis is not zero.
  r.redundantlyRigid = r.rigid && m > 0 && r.stresses > 0;
  for (int e = 0; e < m && r.redundantlyRigid; ++e) {
    r.redundantlyRigid = stressBasis.row(e).norm() > kStressTolerance;
  }
  if (simplex) {
    r.globallyRigid = r.rigid;
  } else if (r.stresses > 0) {
    Eigen::VectorXd c(r.stresses);
    for (int s = 0; s < r.stresses; ++s) c(s) = normal(engine);
    const Eigen::VectorXd w = (stressBasis * c).normalized();
    // Stress matrix Omega: -w_ij off the diagonal, row sums zero.
    Eigen::MatrixXd omega = Eigen::MatrixXd::Zero(n, n);
    for (int e = 0; e < m; ++e) {
      const int i = graph.edges()[e].tail, j = graph.edges()[e].head;
      omega(i, j) -= w(e);
      omega(j, i) -= w(e);
      omega(i, i) += w(e);
      omega(j, j) += w(e);
    }
    r.stressRank = countAbove(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(omega, Eigen::EigenvaluesOnly).eigenvalues(),
                              kStressTolerance);
    r.globallyRigid = r.rigid && r.stressRank == n - d - 1;
  }
  if (r.globallyRigid) {
    r.rigidityClass = RigidityClass::GloballyRigid;
  } else if (r.redundantlyRigid) {
    r.rigidityClass = RigidityClass::RedundantlyRigid;
  } else if (r.minimallyRigid) {
    r.rigidityClass = RigidityClass::MinimallyRigid;
  } else if (r.rigid) {
    r.rigidityClass = RigidityClass::Rigid;
  }
  return r;
}

}  // namespace

std::string describe(RigidityClass c) {
  switch (c) {
    case RigidityClass::NotRigid: return "not rigid";
    case RigidityClass::Rigid: return "rigid";
    case RigidityClass::MinimallyRigid: return "minimally rigid";
    case RigidityClass::RedundantlyRigid: return "redundantly rigid";
    case RigidityClass::GloballyRigid: return "globally rigid";
  }
  return "?";
}

std::string RigidityReport::summary() const {
  char text[240];
  std::snprintf(text, sizeof text, "%s in %dD (%d agent%s, %d edges; rigidity rank %d of %d; %d self-stress%s",
                describe(rigidityClass).c_str(), dimension, agents, agents == 1 ? "" : "s", edges, rank, neededRank, stresses,
                stresses == 1 ? "" : "es");
  std::string line = text;
  if (stressRank >= 0) {
    std::snprintf(text, sizeof text, ", stress matrix rank %d of %d", stressRank, agents - dimension - 1);
    line += text;
  }
  return line + ")";
}

RigidityReport classifyRigidity(const Formation& formation, std::uint64_t seed) {
  std::array<RigidityReport, 3> runs;
  for (std::size_t k = 0; k < runs.size(); ++k) runs[k] = classifyRealization(formation, seed + k);
  // The majority; if all three differ, the middle class (deterministic either way).
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const auto agree = std::count_if(runs.begin(), runs.end(), [&](const RigidityReport& r) {
      return r.rigidityClass == runs[k].rigidityClass;
    });
    if (agree >= 2) return runs[k];
  }
  std::sort(runs.begin(), runs.end(), [](const RigidityReport& a, const RigidityReport& b) {
    return a.rigidityClass < b.rigidityClass;
  });
  return runs[1];
}

}  // namespace vf
