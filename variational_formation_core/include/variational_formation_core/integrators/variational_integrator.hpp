#pragma once

#include "variational_formation_core/integrators/integrator.hpp"

namespace vf {

/// The centralised explicit variational integrator (doc/maths.md §2), agent by agent.
class VariationalIntegrator : public Integrator {
 public:
  VariationalIntegrator(const Formation& formation, const Positions& q0, const Velocities& v0,
                        double timeStep, double dampingGain, StartMethod start);

  void step() override;
  const Positions& positions() const override { return q_; }
  Velocities velocities() const override;
  Momenta momenta() const override;
  double energy() const override;

  /// q_{k-1} (q_0 at k = 0).
  const Positions& previousPositions() const { return qPrev_; }

 private:
  VariationalCoefficients coefficients_;
  StartMethod start_;
  Velocities v0_;
  Positions qPrev_;
  Positions q_;
  Positions qNext_;
  Gradients gradient_;
};

}  // namespace vf
