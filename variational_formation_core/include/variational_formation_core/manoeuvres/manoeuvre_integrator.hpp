#pragma once

#include "variational_formation_core/integrators/integrator.hpp"
#include "variational_formation_core/manoeuvres/manoeuvre_model.hpp"

namespace vf {

/**
 * The centralised variational integrator under a command schedule (doc/maths.md §9): agent by
 * agent, grad_i V_s and the centroid offset r_i from the neighbours' positions, then
 * manoeuvreUpdate / manoeuvreStart. A distributed agent calls the same functions on the same
 * numbers. Without any command the scenario runs through VariationalIntegrator instead (the
 * zero command gives the same numbers, bit for bit; test/core/test_manoeuvre.cpp checks it).
 */
class ManoeuvreIntegrator : public Integrator {
 public:
  /// @throws InvalidInput if the schedule turns and some agent's motion parameters are not exact.
  ManoeuvreIntegrator(const Formation& formation, const Positions& q0, const Velocities& v0,
                      double timeStep, double dampingGain, StartMethod start, CommandSchedule schedule);

  void step() override;
  const Positions& positions() const override { return q_; }
  Velocities velocities() const override;
  /// p+_k of the forced scheme: ((1 + a)/2) v_{k-1} - (h/2)(grad V_s(q_k) - F_h(q_k)), with the
  /// command of interval k - 1 (v_0 at k = 0).
  Momenta momenta() const override;
  /// E_d(q_{k-1}, q_k) with V_s of interval k - 1 (1/2|v_0|^2 + V_s(q_0) at k = 0).
  double energy() const override;
  double commandedScale() const override { return model_.scaleAt(step_); }

  const ManoeuvreModel& model() const { return model_; }
  const std::vector<MotionParameters>& motionParameters() const { return parameters_; }

 private:
  /// f_i at q under gains g, d doubles.
  void forcing(const ManoeuvreGains& g, int agent, const Positions& q, double* out) const;

  VariationalCoefficients coefficients_;
  StartMethod start_;
  ManoeuvreModel model_;
  std::vector<MotionParameters> parameters_;
  Velocities v0_;
  Positions qPrev_, q_, qNext_;
};

}  // namespace vf
