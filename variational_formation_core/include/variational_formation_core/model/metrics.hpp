#pragma once

#include "variational_formation_core/model/formation.hpp"
#include "variational_formation_core/integrators/variational_update.hpp"

namespace vf {

/**
 * Discrete momenta, energy and Noether quantities of doc/maths.md §4-6. All momenta are the
 * unweighted ones (divided by e^{kappa t}), so none of these ever forms e^{kappa t}.
 */

/// p+_{k+1} = ((1 + e^{-kappa h})/2) v_k - (h/2) grad V(q_{k+1}), v_k = (q_{k+1} - q_k)/h.
Momenta discreteMomentumPlus(const Formation& formation, const VariationalCoefficients& c,
                               const Positions& qk, const Positions& qk1);
/// p-_k = ((1 + e^{kappa h})/2) v_k + (h/2) grad V(q_k).
Momenta discreteMomentumMinus(const Formation& formation, const VariationalCoefficients& c,
                                const Positions& qk, const Positions& qk1);

/// The discrete Hamiltonian flow (q_k, p_k) -> (q_{k+1}, p_{k+1}) (paper Section 4): solves
/// p_k = p-_k(q_k, q_{k+1}) for q_{k+1} (explicit here) and returns p+_{k+1}.
void discreteHamiltonianFlow(const Formation& formation, const VariationalCoefficients& c,
                             const Positions& qk, const Momenta& pk, Positions& qk1,
                             Momenta& pk1);

/// E_d(q_k, q_{k+1}) = 1/2 |v_k|^2 + 1/2 (V(q_k) + V(q_{k+1})); under a commanded scale s, V_s
/// with s^2 = scaleSquared (doc/maths.md §9).
double discreteEnergy(const Formation& formation, double timeStep, const Positions& qk,
                      const Positions& qk1, double scaleSquared = 1.0);
/// Per agent: 1/2 |v_{i,k}|^2 + 1/2 (V_i(q_k) + V_i(q_{k+1})), V_i = agentPotential. Sums to E_d.
Eigen::VectorXd agentDiscreteEnergy(const Formation& formation, double timeStep,
                                    const Positions& qk, const Positions& qk1, double scaleSquared = 1.0);
/// E = 1/2 |v|^2 + V(q) (V_s under a commanded scale).
double continuousEnergy(const Formation& formation, const Positions& q, const Velocities& v,
                        double scaleSquared = 1.0);
/// Per agent 1/2 |v_i|^2 + V_i(q).
Eigen::VectorXd agentContinuousEnergy(const Formation& formation, const Positions& q,
                                      const Velocities& v, double scaleSquared = 1.0);

/// P = sum_i p_i (z = 0 in 2D).
Vector3 linearMomentum(const Momenta& p);
/// A = sum_i q_i x p_i (in 2D, only z is nonzero).
Vector3 angularMomentum(const Positions& q, const Momenta& p);

/// Noether's prediction e^{-kappa t_k} X_0 = (e^{-kappa h})^k X_0 (doc/maths.md §6).
Vector3 noetherPrediction(const Vector3& initial, const VariationalCoefficients& c, long step);

/// |X - prediction| / max(|X_0|, 1e-300): the residual the Noether tests bound.
double noetherResidual(const Vector3& value, const Vector3& prediction, const Vector3& initial);

}  // namespace vf
