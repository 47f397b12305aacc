#pragma once

namespace vf {

/**
 * Constant coefficients of the explicit variational update for L = e^{kappa t}(1/2|q'|^2 - V),
 * doc/maths.md §2. They depend on h and kappa only through e^{+-kappa h}: e^{kappa t} is never
 * formed, so long runs cannot overflow.
 */
struct VariationalCoefficients {
  /// @param timeStep h > 0 in seconds. @param dampingGain kappa >= 0 in 1/s.
  VariationalCoefficients(double timeStep, double dampingGain);

  double timeStep;
  double dampingGain;
  /// e^{-kappa h}; equal to the paper's kappa_h = (1 + e^{-kappa h}) / (1 + e^{kappa h}).
  double decay;
  /// 1 + e^{-kappa h}; the paper's hat kappa_h.
  double positionGain;
  /// 2 h^2 / (1 + e^{kappa h}); the paper's bar kappa_h.
  double gradientGain;
  /// 2 h / (1 + e^{kappa h}), used by the variational start.
  double startGain;
};

/**
 * One agent's explicit update (doc/maths.md §2; paper eq. (integrator-explicit), errata fixed):
 * q_{k+2} = (1 + e^{-kappa h}) q_{k+1} - e^{-kappa h} q_k - 2h^2/(1 + e^{kappa h}) grad_i V(q_{k+1}).
 * Both the agent node and the centralised integrator call this function, coordinate by
 * coordinate, so the two paths agree bit for bit.
 * @param dimension d. @param qPrev q_k. @param q q_{k+1}. @param gradient grad_i V(q_{k+1}).
 * @param qNext receives q_{k+2}; d doubles.
 */
inline void variationalUpdate(const VariationalCoefficients& c, int dimension, const double* qPrev,
                              const double* q, const double* gradient, double* qNext) {
  for (int a = 0; a < dimension; ++a) {
    qNext[a] = c.positionGain * q[a] - c.decay * qPrev[a] - c.gradientGain * gradient[a];
  }
}

/**
 * Variational start (doc/maths.md §3): solves p_0 = -D1 L_d^0(q_0, q_1) with p_0 = v_0,
 * q_1 = q_0 + 2h/(1 + e^{kappa h}) (v_0 - h/2 grad V(q_0)). Second order overall.
 */
inline void variationalStart(const VariationalCoefficients& c, int dimension, const double* q0,
                             const double* v0, const double* gradient0, double* q1) {
  for (int a = 0; a < dimension; ++a) {
    q1[a] = q0[a] + c.startGain * (v0[a] - 0.5 * c.timeStep * gradient0[a]);
  }
}

/// The paper's start q_1 = q_0 + h v_0 (Section 6.1). First order overall.
inline void paperStart(const VariationalCoefficients& c, int dimension, const double* q0,
                       const double* v0, double* q1) {
  for (int a = 0; a < dimension; ++a) {
    q1[a] = q0[a] + c.timeStep * v0[a];
  }
}

/**
 * Velocity form of the explicit update (doc/maths.md §2), for an agent that measures its position:
 * v_{k+1} = e^{-kappa h} v_k - 2h/(1 + e^{kappa h}) grad_i V(q_{k+1}), then q_{k+2} = q_{k+1} + h v_{k+1}.
 * Equal to variationalUpdate up to round-off when v_k = (q_{k+1} - q_k)/h.
 * @param v v_k [m/s]. @param gradient grad_i V(q_{k+1}). @param vNext receives v_{k+1}; d doubles.
 */
inline void variationalVelocityUpdate(const VariationalCoefficients& c, int dimension, const double* v,
                                      const double* gradient, double* vNext) {
  for (int a = 0; a < dimension; ++a) {
    vNext[a] = c.decay * v[a] - c.startGain * gradient[a];
  }
}

/// How the two-step scheme gets q_1.
enum class StartMethod { Variational, Paper };

/**
 * One agent's step k -> k + 1 of the centralised integrators: the start at k = 0, the explicit
 * update after. @param gradient grad_i V at step k (unused by the paper's start).
 */
inline void variationalStep(const VariationalCoefficients& c, StartMethod start, long step,
                            int dimension, const double* qPrev, const double* q, const double* v0,
                            const double* gradient, double* qNext) {
  if (step > 0) {
    // doc/maths.md §2, explicit update; paper eq. (integrator-explicit), errata fixed.
    variationalUpdate(c, dimension, qPrev, q, gradient, qNext);
  } else if (start == StartMethod::Variational) {
    variationalStart(c, dimension, q, v0, gradient, qNext);
  } else {
    paperStart(c, dimension, q, v0, qNext);
  }
}

}  // namespace vf
