#include "variational_formation_core/integrators/variational_integrator.hpp"

#include "variational_formation_core/model/metrics.hpp"

namespace vf {

VariationalIntegrator::VariationalIntegrator(const Formation& formation, const Positions& q0,
                                             const Velocities& v0, double timeStep,
                                             double dampingGain, StartMethod start)
    : Integrator(formation, timeStep, dampingGain),
      coefficients_(timeStep, dampingGain),
      start_(start),
      v0_(v0),
      qPrev_(q0),
      q_(q0),
      qNext_(q0),
      gradient_(Gradients::Zero(q0.rows(), q0.cols())) {}

void VariationalIntegrator::step() {
  const int d = formation_.dimension();
  const int n = formation_.agentCount();
  for (int i = 0; i < n; ++i) {
    double* g = gradient_.col(i).data();
    forces_.agentGradient(i, q_, g);
    variationalStep(coefficients_, start_, step_, d, qPrev_.col(i).data(), q_.col(i).data(),
                    v0_.col(i).data(), g, qNext_.col(i).data());
  }
  forces_.filterStep(q_, step_, qNext_);  // doc/maths.md §10, after every agent's update
  qPrev_.swap(q_);
  q_.swap(qNext_);
  ++step_;
}

Velocities VariationalIntegrator::velocities() const {
  if (step_ == 0) return v0_;
  return (q_ - qPrev_) / timeStep_;
}

Momenta VariationalIntegrator::momenta() const {
  if (step_ == 0) return v0_;
  return discreteMomentumPlus(formation_, coefficients_, qPrev_, q_);
}

double VariationalIntegrator::energy() const {
  if (step_ == 0) return continuousEnergy(formation_, q_, v0_);
  return discreteEnergy(formation_, timeStep_, qPrev_, q_);
}

}  // namespace vf
