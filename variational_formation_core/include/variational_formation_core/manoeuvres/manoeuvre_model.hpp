#pragma once

#include <vector>

#include "variational_formation_core/manoeuvres/command_schedule.hpp"
#include "variational_formation_core/model/motion_parameters.hpp"
#include "variational_formation_core/integrators/variational_update.hpp"

namespace vf {

/**
 * The forcing of one interval [t_k, t_{k+1}] under a command, as it enters the update
 * (doc/maths.md §9): the displacement f_i = b F_h(q)_i = translation + rotation r_i added to
 * q_{k+2}, where b = 2h^2/(1 + e^{kappa h}) and r_i is the agent's centroid offset. With
 * a = e^{-kappa h}, theta = h |omega*| and K = [e]x, e the unit axis of omega*:
 *   translation = (1 - a) h v*                      [m]
 *   rotation    = (1 - a) sin(theta) K + (1 + a)(1 - cos theta) K^2   [1]
 * so that rigid motion at v*, omega* with the shape scaled by s is an exact discrete solution.
 */
struct ManoeuvreGains {
  double translation[3] = {0.0, 0.0, 0.0};
  /// h tanh(kappa h / 2) v* [m]: the start's translation (see manoeuvreStart).
  double startTranslation[3] = {0.0, 0.0, 0.0};
  double rotation[3][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
  /// s^2: V_s uses the squared desired distances s^2 d_ij^2.
  double scaleSquared = 1.0;
  bool rotates = false;
};

/// The gains of a (validated) command at step h and damping kappa.
ManoeuvreGains manoeuvreGains(const Command& command, const VariationalCoefficients& c);

/// The trapezoid's node forcing at t_{k+1} between intervals k and k+1: the mean of the two.
ManoeuvreGains nodeGains(const ManoeuvreGains& before, const ManoeuvreGains& after);

/// Coordinate a of the rotation part of f_i, rotation r_i [m]; offset (r_i, d doubles) is read
/// only if the gains rotate.
inline double rotationForcing(const ManoeuvreGains& g, int dimension, int a, const double* offset) {
  double f = 0.0;
  if (g.rotates) {
    for (int b = 0; b < dimension; ++b) f += g.rotation[a][b] * offset[b];
  }
  return f;
}

/// Coordinate a of f_i = translation + rotation r_i [m].
inline double manoeuvreForcing(const ManoeuvreGains& g, int dimension, int a, const double* offset) {
  return g.translation[a] + rotationForcing(g, dimension, a, offset);
}

/**
 * One agent's forced update (doc/maths.md §9), the command's counterpart of variationalUpdate:
 * q_{k+2} = (1 + a) q_{k+1} - a q_k - b grad_i V_s(q_{k+1}) + f_i, f_i = translation + rotation r_i.
 * @param gradient grad_i V_s(q_{k+1}) with s^2 = g.scaleSquared. @param offset r_i at q_{k+1}
 * (read only if g.rotates). All arrays d doubles.
 */
inline void manoeuvreUpdate(const VariationalCoefficients& c, const ManoeuvreGains& g, int dimension,
                            const double* qPrev, const double* q, const double* gradient,
                            const double* offset, double* qNext) {
  for (int a = 0; a < dimension; ++a) {
    const double f = manoeuvreForcing(g, dimension, a, offset);
    qNext[a] = c.positionGain * q[a] - c.decay * qPrev[a] - c.gradientGain * gradient[a] + f;
  }
}

/**
 * The forced variational start (doc/maths.md §9): today's variational start in the frame moving
 * at v*, with half the trapezoid's rotation force at q_0:
 * q_1 = q_0 + h v* + 2h/(1 + e^{kappa h}) (v_0 - v* - h/2 grad V_s(q_0)) + (rotation r_i(q_0))/2,
 * computed as q_0 + 2h/(1 + e^{kappa h})(v_0 - h/2 grad) + h tanh(kappa h/2) v* + rotation r_i/2.
 * Second order; a pure translation then is today's run in the moving frame from the first step.
 */
inline void manoeuvreStart(const VariationalCoefficients& c, const ManoeuvreGains& g, int dimension,
                           const double* q0, const double* v0, const double* gradient0,
                           const double* offset0, double* q1) {
  for (int a = 0; a < dimension; ++a) {
    const double f = g.startTranslation[a] + 0.5 * rotationForcing(g, dimension, a, offset0);
    q1[a] = q0[a] + c.startGain * (v0[a] - 0.5 * c.timeStep * gradient0[a]) + f;
  }
}

/**
 * The commands of a run as the update needs them: the schedule and each entry's gains,
 * computed once. The centralised integrator and each distributed agent hold one and ask it for
 * the same gains, so both paths use identical numbers.
 */
class ManoeuvreModel {
 public:
  ManoeuvreModel(const VariationalCoefficients& coefficients, CommandSchedule schedule);

  /// Appends a step-stamped command (see CommandSchedule::add).
  void add(long step, const Command& command);
  /// A step-stamped command that replaces the schedule from its step on (CommandSchedule::replaceFrom).
  void replaceFrom(long step, const Command& command);
  const CommandSchedule& schedule() const { return schedule_; }
  /// Gains of interval k.
  const ManoeuvreGains& intervalGains(long step) const;
  /// Gains of the update at step k (k -> k + 1): interval 0's at k = 0 (the start), else the
  /// node mean of intervals k - 1 and k (just one of them when both have the same entry).
  ManoeuvreGains updateGains(long step) const;
  /// The scale s of interval k - 1 (the one that ends at t_k; interval 0's at k = 0).
  double scaleAt(long step) const;

 private:
  VariationalCoefficients coefficients_;
  CommandSchedule schedule_;
  ManoeuvreGains zero_;
  std::vector<ManoeuvreGains> gains_;  // one per schedule entry
};

}  // namespace vf
