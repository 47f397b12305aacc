#include "variational_formation_core/model/sparse_spectrum.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseQR>

namespace vf {

Eigen::SparseMatrix<double> sparseHessian(const Formation& formation, const Positions& q) {
  const int d = formation.dimension();
  const Eigen::Index size = static_cast<Eigen::Index>(d) * formation.agentCount();
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(formation.edges().size() * 4 * static_cast<std::size_t>(d * d));
  for (const Edge& e : formation.edges()) {
    const Eigen::VectorXd z = q.col(e.tail) - q.col(e.head);
    const double gamma = z.squaredNorm() - e.desiredDistanceSquared;
    for (int r = 0; r < d; ++r) {
      for (int c = 0; c < d; ++c) {
        // d/dz [gamma z] = gamma I + 2 z z^T, as Formation::hessian.
        const double b = (r == c ? gamma : 0.0) + 2.0 * z(r) * z(c);
        entries.emplace_back(d * e.tail + r, d * e.tail + c, b);
        entries.emplace_back(d * e.head + r, d * e.head + c, b);
        entries.emplace_back(d * e.tail + r, d * e.head + c, -b);
        entries.emplace_back(d * e.head + r, d * e.tail + c, -b);
      }
    }
  }
  Eigen::SparseMatrix<double> h(size, size);
  h.setFromTriplets(entries.begin(), entries.end());
  return h;
}

Eigen::SparseMatrix<double> sparseRigidityMatrix(const Formation& formation, const Positions& q) {
  const int d = formation.dimension();
  const auto& edges = formation.edges();
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(edges.size() * 2 * static_cast<std::size_t>(d));
  for (std::size_t row = 0; row < edges.size(); ++row) {
    const Edge& e = edges[row];
    for (int c = 0; c < d; ++c) {
      const double z = q(c, e.tail) - q(c, e.head);
      entries.emplace_back(static_cast<int>(row), d * e.tail + c, z);
      entries.emplace_back(static_cast<int>(row), d * e.head + c, -z);
    }
  }
  Eigen::SparseMatrix<double> r(static_cast<Eigen::Index>(edges.size()),
                                static_cast<Eigen::Index>(d) * formation.agentCount());
  r.setFromTriplets(entries.begin(), entries.end());
  return r;
}

double largestEigenvalue(const Eigen::SparseMatrix<double>& a) {
  const Eigen::Index n = a.rows();
  if (n == 0) return 0.0;
  const Eigen::Index maxSteps = std::min<Eigen::Index>(n, 600);
  // A fixed pseudo-random start: deterministic, and not orthogonal to the top eigenvector
  // (a constant vector would be, for the translation-invariant Hessian).
  std::mt19937_64 generator(1);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::VectorXd v(n);
  for (Eigen::Index i = 0; i < n; ++i) v(i) = uniform(generator);
  v.normalize();
  // The three-term recurrence only, O(n) memory and work per step: without reorthogonalisation
  // the Ritz values gain copies of converged eigenvalues ("ghosts"), never a value above
  // lambda_max, so the top one still rises to lambda_max. Full reorthogonalisation against every
  // earlier vector cost O(n m^2): 17 of the 20 s of loading a 10,000-agent ring.
  Eigen::VectorXd previous = Eigen::VectorXd::Zero(n);
  std::vector<double> alpha, beta;
  double top = 0.0;
  int steady = 0;  // consecutive checks in which the top Ritz value stood still
  for (Eigen::Index j = 0; j < maxSteps; ++j) {
    Eigen::VectorXd w = a * v;
    if (j > 0) w -= beta.back() * previous;
    alpha.push_back(v.dot(w));
    w -= alpha.back() * v;
    const double b = w.norm();
    const Eigen::Index m = j + 1;
    if (m % 8 == 0 || b == 0.0 || m == maxSteps) {
      // Eigenvalues only (O(m^2)): the top Ritz value rises monotonically to lambda_max, and
      // converges fast once it moves by less than 1e-14 of itself twice in a row.
      Eigen::VectorXd diagonal = Eigen::Map<Eigen::VectorXd>(alpha.data(), m);
      Eigen::VectorXd sub = m > 1 ? Eigen::VectorXd(Eigen::Map<Eigen::VectorXd>(beta.data(), m - 1))
                                  : Eigen::VectorXd();
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> t;
      t.computeFromTridiagonal(diagonal, sub, Eigen::EigenvaluesOnly);
      const double before = top;
      top = t.eigenvalues()(m - 1);
      steady = std::abs(top - before) <= 1e-14 * std::abs(top) ? steady + 1 : 0;
      if (steady >= 2) break;
    }
    if (b == 0.0) break;
    beta.push_back(b);
    previous = v;
    v = w / b;
  }
  return top;
}

int sparseRank(const Eigen::SparseMatrix<double>& a, double relativeTolerance) {
  if (a.nonZeros() == 0) return 0;
  double largest = 0.0;
  for (Eigen::Index c = 0; c < a.cols(); ++c) largest = std::max(largest, a.col(c).norm());
  // The columns in the formation's own order: COLAMD's ordering fills a ring's R almost densely
  // (0.95 M entries at 1000 agents against 19 k, 2.7 s against 5 ms; 10,000 agents take 0.5 s),
  // and formations are numbered along their shape (make_scenario's generators are).
  Eigen::SparseQR<Eigen::SparseMatrix<double>, Eigen::NaturalOrdering<int>> qr;
  qr.setPivotThreshold(relativeTolerance * std::max(1.0, largest));
  Eigen::SparseMatrix<double> compressed = a;
  compressed.makeCompressed();
  qr.compute(compressed);
  return static_cast<int>(qr.rank());
}

}  // namespace vf
