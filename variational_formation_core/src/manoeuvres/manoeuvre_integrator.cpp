#include "variational_formation_core/manoeuvres/manoeuvre_integrator.hpp"

#include "variational_formation_core/model/metrics.hpp"

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/validation.hpp"

namespace vf {

ManoeuvreIntegrator::ManoeuvreIntegrator(const Formation& formation, const Positions& q0,
                                         const Velocities& v0, double timeStep, double dampingGain,
                                         StartMethod start, CommandSchedule schedule)
    : Integrator(formation, timeStep, dampingGain),
      coefficients_(timeStep, dampingGain),
      start_(start),
      model_(coefficients_, std::move(schedule)),
      v0_(v0),
      qPrev_(q0),
      q_(q0),
      qNext_(q0) {
  validateDynamics(timeStep, dampingGain);
  for (int i = 0; i < formation.agentCount(); ++i) {
    parameters_.push_back(vf::motionParameters(formation, i));
    if (model_.schedule().rotates() && !parameters_.back().exact) {
      throw InvalidInput("angular_rate: " + parameters_.back().problem);
    }
  }
}

void ManoeuvreIntegrator::forcing(const ManoeuvreGains& g, int agent, const Positions& q, double* out) const {
  const int d = formation_.dimension();
  double r[3] = {0.0, 0.0, 0.0};
  if (g.rotates) forces_.centroidOffset(parameters_[static_cast<std::size_t>(agent)], agent, q, r);
  for (int a = 0; a < d; ++a) out[a] = manoeuvreForcing(g, d, a, r);
}

void ManoeuvreIntegrator::step() {
  const int d = formation_.dimension();
  const int n = formation_.agentCount();
  const ManoeuvreGains g = model_.updateGains(step_);
  double gradient[3], offset[3] = {0.0, 0.0, 0.0};
  for (int i = 0; i < n; ++i) {
    forces_.agentGradient(i, q_, g.scaleSquared, gradient);
    if (g.rotates) forces_.centroidOffset(parameters_[static_cast<std::size_t>(i)], i, q_, offset);
    double* next = qNext_.col(i).data();
    if (step_ > 0) {
      // doc/maths.md §9, the forced update.
      manoeuvreUpdate(coefficients_, g, d, qPrev_.col(i).data(), q_.col(i).data(), gradient, offset, next);
    } else if (start_ == StartMethod::Variational) {
      manoeuvreStart(coefficients_, g, d, q_.col(i).data(), v0_.col(i).data(), gradient, offset, next);
    } else {
      paperStart(coefficients_, d, q_.col(i).data(), v0_.col(i).data(), next);
    }
  }
  forces_.filterStep(q_, step_, qNext_);  // doc/maths.md §10, after every agent's update
  qPrev_.swap(q_);
  q_.swap(qNext_);
  ++step_;
}

Velocities ManoeuvreIntegrator::velocities() const {
  if (step_ == 0) return v0_;
  return (q_ - qPrev_) / timeStep_;
}

Momenta ManoeuvreIntegrator::momenta() const {
  if (step_ == 0) return v0_;
  const ManoeuvreGains& g = model_.intervalGains(step_ - 1);
  const int d = formation_.dimension();
  Momenta p(d, formation_.agentCount());
  double gradient[3], f[3];
  for (int i = 0; i < formation_.agentCount(); ++i) {
    forces_.agentGradient(i, q_, g.scaleSquared, gradient);
    forcing(g, i, q_, f);
    for (int a = 0; a < d; ++a) {
      const double v = (q_(a, i) - qPrev_(a, i)) / timeStep_;
      // (h/2) F_h = (h/2) f / b = f / (2 startGain)
      p(a, i) = 0.5 * coefficients_.positionGain * v - 0.5 * timeStep_ * gradient[a] +
                f[a] / (2.0 * coefficients_.startGain);
    }
  }
  return p;
}

double ManoeuvreIntegrator::energy() const {
  if (step_ == 0) return continuousEnergy(formation_, q_, v0_, model_.intervalGains(0).scaleSquared);
  return discreteEnergy(formation_, timeStep_, qPrev_, q_, model_.intervalGains(step_ - 1).scaleSquared);
}

}  // namespace vf
