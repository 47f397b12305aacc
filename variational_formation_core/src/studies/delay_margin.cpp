#include "variational_formation_core/studies/delay_margin.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/integrators/variational_update.hpp"

namespace vf {

namespace {

/// H_diag and H_off of the Hessian at q*.
void splitHessian(const Formation& formation, Eigen::MatrixXd& Hdiag, Eigen::MatrixXd& Hoff) {
  const int d = formation.dimension();
  const Eigen::MatrixXd H = formation.hessian(formation.desiredShape());
  Hdiag = Eigen::MatrixXd::Zero(H.rows(), H.cols());
  for (Eigen::Index i = 0; i < H.rows(); i += d) Hdiag.block(i, i, d, d) = H.block(i, i, d, d);
  Hoff = H - Hdiag;
}

int nullity(const Eigen::MatrixXd& H) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> hs(H, Eigen::EigenvaluesOnly);
  const double scale = std::max(1.0, hs.eigenvalues().cwiseAbs().maxCoeff());
  int r = 0;
  for (Eigen::Index k = 0; k < hs.eigenvalues().size(); ++k) {
    r += std::abs(hs.eigenvalues()(k)) <= 1e-9 * scale ? 1 : 0;
  }
  return r;
}

constexpr double kPi = 3.14159265358979323846;

}  // namespace

Eigen::MatrixXd delayedCompanionMatrix(const Formation& formation, double timeStep,
                                       double dampingGain, long delaySteps) {
  const VariationalCoefficients c(timeStep, dampingGain);
  Eigen::MatrixXd Hdiag, Hoff;
  splitHessian(formation, Hdiag, Hoff);
  const Eigen::Index N = Hdiag.rows();
  const long D = delaySteps;
  const Eigen::Index B = std::max<long>(2, D + 1);
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(N, N);
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(B * N, B * N);
  C.block(0, 0, N, N) = c.positionGain * I - c.gradientGain * Hdiag;
  C.block(0, N, N, N) -= c.decay * I;
  C.block(0, D * N, N, N) -= c.gradientGain * Hoff;  // D = 0: H_off joins H_diag at x^k
  for (Eigen::Index b = 1; b < B; ++b) C.block(b * N, (b - 1) * N, N, N) = I;
  return C;
}

DelaySpectrum delaySpectrum(const Formation& formation, double timeStep, double dampingGain,
                            long delaySteps) {
  DelaySpectrum s;
  s.delaySteps = delaySteps;
  // Fixed modes: the null space of the Hessian at q* (d(d+1)/2 for a rigid formation).
  s.fixedModes = nullity(formation.hessian(formation.desiredShape()));
  const Eigen::EigenSolver<Eigen::MatrixXd> es(
      delayedCompanionMatrix(formation, timeStep, dampingGain, delaySteps), false);
  const Eigen::VectorXcd lambda = es.eigenvalues();
  std::vector<double> distance(static_cast<std::size_t>(lambda.size()));
  std::vector<Eigen::Index> order(distance.size());
  for (Eigen::Index k = 0; k < lambda.size(); ++k) {
    distance[k] = std::abs(lambda(k) - 1.0);
    order[k] = k;
    s.eigenvaluesAtOne += distance[k] < 1e-7 ? 1 : 0;
  }
  std::sort(order.begin(), order.end(),
            [&](Eigen::Index a, Eigen::Index b) { return distance[a] < distance[b]; });
  for (std::size_t r = 0; r < order.size(); ++r) {
    if (static_cast<int>(r) < s.fixedModes) {
      s.excludedDistance = std::max(s.excludedDistance, distance[order[r]]);
    } else {
      s.spectralRadius = std::max(s.spectralRadius, std::abs(lambda(order[r])));
    }
  }
  return s;
}


int unstableRootCount(const Formation& formation, double timeStep, double dampingGain,
                      long delaySteps) {
  if (!(dampingGain > 0.0)) return -1;
  Eigen::MatrixXd Hdiag, Hoff;
  splitHessian(formation, Hdiag, Hoff);
  const int r = nullity(Hdiag + Hoff);
  const VariationalCoefficients c(timeStep, dampingGain);
  const Eigen::Index N = Hdiag.rows();
  const double e = c.decay, g = c.gradientGain;
  const double D = static_cast<double>(delaySteps);
  // arg of Q(theta) = det(p I + g H_diag + g e^{-i D theta} H_off) / (e^{i theta} - 1)^r,
  // p = lambda - (1 + e) + e / lambda on lambda = e^{i theta}; chi_D = lambda^{max(D,1) N} Q (lambda - 1)^r.
  const auto argQ = [&](double theta) {
    const std::complex<double> p((1.0 + e) * (std::cos(theta) - 1.0), (1.0 - e) * std::sin(theta));
    const std::complex<double> z = std::polar(g, -D * theta);
    Eigen::MatrixXcd M = g * Hdiag.cast<std::complex<double>>() + z * Hoff.cast<std::complex<double>>();
    M.diagonal().array() += p;
    const Eigen::PartialPivLU<Eigen::MatrixXcd> lu(M);
    double arg = 0.0;
    for (Eigen::Index k = 0; k < N; ++k) arg += std::arg(lu.matrixLU()(k, k));
    if (lu.permutationP().determinant() < 0) arg += kPi;
    return arg - r * 0.5 * (theta + kPi);  // arg (e^{i theta} - 1) = (theta + pi) / 2
  };
  const auto wrap = [](double a) { return a - 2.0 * kPi * std::floor((a + kPi) / (2.0 * kPi)); };
  // Q is conjugate-symmetric and real at theta -> 0+ and at pi: its winding on the circle is
  // twice its arg change over (0, pi), divided by 2 pi. The grid is geometric near 0, where the
  // slow modes crowd near lambda = 1, uniform beyond; each interval is halved until its arg
  // change is below pi/8, so a root near the circle is passed in small steps.
  std::vector<double> grid;
  const double split = 0.2;
  for (int s = 0; s < 400; ++s) grid.push_back(1e-5 * std::pow(split / 1e-5, s / 400.0));
  const int uniform = std::max(400, 64 * static_cast<int>(delaySteps + 2));
  for (int s = 0; s <= uniform; ++s) grid.push_back(split + (kPi - split) * s / uniform);
  double total = 0.0;
  double a = grid.front(), argA = argQ(a);
  for (std::size_t s = 1; s < grid.size(); ++s) {
    std::vector<std::pair<double, double>> stack{{grid[s], argQ(grid[s])}};
    while (!stack.empty()) {
      const auto [tb, argB] = stack.back();
      const double step = wrap(argB - argA);
      if (std::abs(step) < 0.125 * kPi || tb - a < 1e-13) {
        total += step;
        a = tb;
        argA = argB;
        stack.pop_back();
      } else {
        const double mid = 0.5 * (a + tb);
        stack.push_back({mid, argQ(mid)});
      }
    }
  }
  const double winding = total / kPi;
  const long rounded = std::lround(winding);
  if (std::abs(winding - static_cast<double>(rounded)) > 0.1) return -1;
  return static_cast<int>(N - r - rounded);
}

bool DelayMargin::confirmed() const {
  for (const DelaySpectrum& s : checks) {
    if (s.stable() != (s.delaySteps <= margin)) return false;
  }
  return true;
}

DelayMargin predictDelayMargin(const Formation& formation, double timeStep, double dampingGain,
                               long maxDelay, long maxCompanionSize) {
  if (formation.edges().empty()) {
    throw InvalidInput("edges: the formation has no edges, so no agent has a neighbour and a delay changes nothing");
  }
  if (maxDelay < 0) throw InvalidInput("--max-delay: must be >= 0");
  auto start = std::chrono::steady_clock::now();
  DelayMargin m;
  m.capped = true;
  for (long D = 0; D <= maxDelay; ++D) {
    m.unstableRoots.push_back(unstableRootCount(formation, timeStep, dampingGain, D));
    if (m.unstableRoots.back() != 0) {
      m.capped = false;
      break;
    }
    m.margin = D;
  }
  m.scanSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // The companion matrix has the last word: from the first D the count calls unstable, walk
  // up while it is stable, else down while D - 1 is unstable (within maxCompanionSize rows).
  start = std::chrono::steady_clock::now();
  const long N = formation.dimension() * formation.agentCount();
  const auto affordable = [&](long D) { return D >= 0 && std::max(2L, D + 1) * N <= maxCompanionSize; };
  if (!m.capped && affordable(m.margin + 1)) {
    long D = m.margin + 1;
    m.checks.push_back(delaySpectrum(formation, timeStep, dampingGain, D));
    while (m.checks.back().stable() && affordable(D + 1)) {
      m.margin = D;
      m.checks.push_back(delaySpectrum(formation, timeStep, dampingGain, ++D));
    }
    if (m.checks.back().stable()) m.margin = D;  // stable up to what can be checked
    D = m.margin;
    while (m.checks.size() == 1 && affordable(D) && D == m.margin) {
      m.checks.push_back(delaySpectrum(formation, timeStep, dampingGain, D));
      if (m.checks.back().stable()) break;
      m.margin = --D;
      m.checks.erase(m.checks.begin());  // keep walking down
    }
  } else if (affordable(m.margin)) {
    m.checks.push_back(delaySpectrum(formation, timeStep, dampingGain, m.margin));
  }
  m.checkSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return m;
}

}  // namespace vf
