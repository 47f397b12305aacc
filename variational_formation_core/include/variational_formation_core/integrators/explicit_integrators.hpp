#pragma once

#include "variational_formation_core/integrators/integrator.hpp"

namespace vf {

/// State (q, v) of a first-order form q' = v, v' = -kappa v - grad V.
class FirstOrderIntegrator : public Integrator {
 public:
  const Positions& positions() const override { return q_; }
  Velocities velocities() const override { return v_; }
  Momenta momenta() const override { return v_; }
  double energy() const override;

  /// @param q0 [m], @param v0 [m/s], d x n each; @param timeStep h [s]; @param dampingGain
  /// kappa [1/s]. Public so that each scheme inherits it; the class stays abstract (step()).
  FirstOrderIntegrator(const Formation& formation, const Positions& q0, const Velocities& v0,
                       double timeStep, double dampingGain);

 protected:
  /// a = -kappa v - grad V(q).
  void acceleration(const Positions& q, const Velocities& v, Accelerations& out) const;

  Positions q_;
  Velocities v_;
};

/// Explicit Euler on (q, v): the paper's comparison (Section 6.1).
class ExplicitEulerIntegrator : public FirstOrderIntegrator {
 public:
  using FirstOrderIntegrator::FirstOrderIntegrator;
  void step() override;

 private:
  Accelerations a_;
};

/// Classical fourth-order Runge-Kutta on (q, v): the accuracy baseline.
class RungeKutta4Integrator : public FirstOrderIntegrator {
 public:
  using FirstOrderIntegrator::FirstOrderIntegrator;
  void step() override;

 private:
  // Stage slopes: k*q_ are velocities, k*v_ accelerations; qs_, vs_ the stage state.
  Velocities k1q_, k2q_, k3q_, k4q_, vs_;
  Accelerations k1v_, k2v_, k3v_, k4v_;
  Positions qs_;
};

}  // namespace vf
