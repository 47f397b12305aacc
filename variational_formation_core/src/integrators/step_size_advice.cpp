#include "variational_formation_core/integrators/step_size_advice.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "variational_formation_core/model/sparse_spectrum.hpp"

namespace vf {

double maxStiffnessFrequency(const Formation& formation, const Positions& q) {
  if (formation.edges().empty()) return 0.0;
  double lambda = 0.0;
  if (formation.dimension() * formation.agentCount() <= kDenseSpectrumLimit) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(formation.hessian(q), Eigen::EigenvaluesOnly);
    lambda = solver.eigenvalues().maxCoeff();
  } else {
    // A dense eigensolver is O((n d)^3): 20 s at 1000 agents, at every load (doc/benchmarks.md).
    lambda = largestEigenvalue(sparseHessian(formation, q));
  }
  return lambda > 0.0 ? std::sqrt(lambda) : 0.0;
}

double minStiffnessFrequency(const Formation& formation, const Positions& q) {
  if (formation.edges().empty()) return 0.0;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(formation.hessian(q), Eigen::EigenvaluesOnly);
  const Eigen::VectorXd& lambda = solver.eigenvalues();  // ascending
  const double floor = 1e-9 * lambda.maxCoeff();
  for (Eigen::Index i = 0; i < lambda.size(); ++i) {
    if (lambda(i) > floor) return std::sqrt(lambda(i));
  }
  return 0.0;
}

bool isLinearlyStable(double timeStep, double frequency, double dampingGain) {
  if (!(frequency > 0.0)) return true;
  const double x = 0.5 * dampingGain * timeStep;
  const double lhs = timeStep * frequency, rhs = 2.0 * std::cosh(x);
  if (std::isfinite(lhs) && std::isfinite(rhs)) return lhs < rhs;
  // Overflow (absurd h or kappa): compare logs, log(2 cosh x) = |x| + log1p(e^{-2|x|}).
  return std::log(timeStep) + std::log(frequency) < std::abs(x) + std::log1p(std::exp(-2.0 * std::abs(x)));
}

double stableTimeStepLimit(double frequency, double dampingGain) {
  if (!(frequency > 0.0)) return std::numeric_limits<double>::infinity();
  // f(h) = h w - 2 cosh(kappa h / 2): f(0) = -2; unstable where f > 0. f is concave,
  // maximal where w = kappa sinh(kappa h / 2).
  const auto f = [&](double h) { return h * frequency - 2.0 * std::cosh(0.5 * dampingGain * h); };
  double hi = 2.0 / frequency;  // the undamped limit
  if (dampingGain > 0.0) {
    const double peak = 2.0 / dampingGain * std::asinh(frequency / dampingGain);
    if (f(peak) <= 0.0) return std::numeric_limits<double>::infinity();
    hi = peak;
  } else {
    return hi;
  }
  double lo = 0.0;  // f(lo) < 0 <= f(hi)
  for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) < 0.0 ? lo : hi) = mid;
  }
  return lo;
}

StepSizeAdvice adviseTimeStep(const Formation& formation, const Positions& q0, double timeStep,
                              double dampingGain, const std::string& field) {
  StepSizeAdvice advice{};
  advice.frequency = std::max(maxStiffnessFrequency(formation, q0),
                              maxStiffnessFrequency(formation, formation.desiredShape()));
  advice.limit = stableTimeStepLimit(advice.frequency, dampingGain);
  advice.exceeded = !isLinearlyStable(timeStep, advice.frequency, dampingGain);
  if (advice.exceeded) {
    std::ostringstream msg;
    msg.precision(4);
    msg << field << ": h = " << timeStep << " exceeds the linear stability limit "
        << advice.limit << " s (largest Hessian frequency w = " << advice.frequency
        << " 1/s; stable iff h w < 2 cosh(kappa h / 2))";
    advice.message = msg.str();
  }
  return advice;
}

}  // namespace vf
