#include "variational_formation_core/integrators/explicit_integrators.hpp"

#include "variational_formation_core/model/metrics.hpp"

namespace vf {

FirstOrderIntegrator::FirstOrderIntegrator(const Formation& formation, const Positions& q0,
                                           const Velocities& v0, double timeStep,
                                           double dampingGain)
    : Integrator(formation, timeStep, dampingGain), q_(q0), v_(v0) {}

double FirstOrderIntegrator::energy() const { return continuousEnergy(formation_, q_, v_); }

// Paper eq. (formation3): v' = -kappa v - grad V(q).
void FirstOrderIntegrator::acceleration(const Positions& q, const Velocities& v,
                                        Accelerations& out) const {
  forces_.gradient(q, out);
  out = -dampingGain_ * v - out;
}

void ExplicitEulerIntegrator::step() {
  acceleration(q_, v_, a_);
  q_ += timeStep_ * v_;
  v_ += timeStep_ * a_;
  ++step_;
}

void RungeKutta4Integrator::step() {
  const double h = timeStep_;
  k1q_ = v_;
  acceleration(q_, v_, k1v_);
  qs_ = q_ + 0.5 * h * k1q_;
  vs_ = v_ + 0.5 * h * k1v_;
  k2q_ = vs_;
  acceleration(qs_, vs_, k2v_);
  qs_ = q_ + 0.5 * h * k2q_;
  vs_ = v_ + 0.5 * h * k2v_;
  k3q_ = vs_;
  acceleration(qs_, vs_, k3v_);
  qs_ = q_ + h * k3q_;
  vs_ = v_ + h * k3v_;
  k4q_ = vs_;
  acceleration(qs_, vs_, k4v_);
  q_ += (h / 6.0) * (k1q_ + 2.0 * k2q_ + 2.0 * k3q_ + k4q_);
  v_ += (h / 6.0) * (k1v_ + 2.0 * k2v_ + 2.0 * k3v_ + k4v_);
  ++step_;
}

}  // namespace vf
