#include "variational_formation_core/model/metrics.hpp"

#include <algorithm>
#include <cmath>

namespace vf {

Momenta discreteMomentumPlus(const Formation& formation, const VariationalCoefficients& c,
                               const Positions& qk, const Positions& qk1) {
  Gradients grad;
  formation.gradient(qk1, grad);
  const Velocities v = (qk1 - qk) / c.timeStep;
  return (0.5 * c.positionGain) * v - (0.5 * c.timeStep) * grad;
}

Momenta discreteMomentumMinus(const Formation& formation, const VariationalCoefficients& c,
                                const Positions& qk, const Positions& qk1) {
  Gradients grad;
  formation.gradient(qk, grad);
  const Velocities v = (qk1 - qk) / c.timeStep;
  // (1 + e^{kappa h}) / 2 = (2h / startGain) / 2 = h / startGain
  return (c.timeStep / c.startGain) * v + (0.5 * c.timeStep) * grad;
}

void discreteHamiltonianFlow(const Formation& formation, const VariationalCoefficients& c,
                             const Positions& qk, const Momenta& pk, Positions& qk1,
                             Momenta& pk1) {
  // p_k = ((1 + e^{kappa h})/2) v_k + (h/2) grad V(q_k)  =>  v_k = startGain/h (p_k - h/2 grad)
  Gradients grad;
  formation.gradient(qk, grad);
  qk1 = qk + c.startGain * (pk - (0.5 * c.timeStep) * grad);
  pk1 = discreteMomentumPlus(formation, c, qk, qk1);
}

double discreteEnergy(const Formation& formation, double timeStep, const Positions& qk,
                      const Positions& qk1, double scaleSquared) {
  const double kinetic = 0.5 * ((qk1 - qk) / timeStep).squaredNorm();
  return kinetic + 0.5 * (formation.scaledPotential(qk, scaleSquared) + formation.scaledPotential(qk1, scaleSquared));
}

Eigen::VectorXd agentDiscreteEnergy(const Formation& formation, double timeStep,
                                    const Positions& qk, const Positions& qk1, double scaleSquared) {
  Eigen::VectorXd e(formation.agentCount());
  for (int i = 0; i < formation.agentCount(); ++i) {
    const double kinetic = 0.5 * ((qk1.col(i) - qk.col(i)) / timeStep).squaredNorm();
    e(i) = kinetic +
           0.5 * (formation.agentPotential(i, qk, scaleSquared) + formation.agentPotential(i, qk1, scaleSquared));
  }
  return e;
}

double continuousEnergy(const Formation& formation, const Positions& q, const Velocities& v,
                        double scaleSquared) {
  return 0.5 * v.squaredNorm() + formation.scaledPotential(q, scaleSquared);
}

Eigen::VectorXd agentContinuousEnergy(const Formation& formation, const Positions& q,
                                      const Velocities& v, double scaleSquared) {
  Eigen::VectorXd e(formation.agentCount());
  for (int i = 0; i < formation.agentCount(); ++i) {
    e(i) = 0.5 * v.col(i).squaredNorm() + formation.agentPotential(i, q, scaleSquared);
  }
  return e;
}

Vector3 linearMomentum(const Momenta& p) {
  Vector3 total = Vector3::Zero();
  for (Eigen::Index i = 0; i < p.cols(); ++i) {
    for (Eigen::Index a = 0; a < p.rows(); ++a) total(a) += p(a, i);
  }
  return total;
}

Vector3 angularMomentum(const Positions& q, const Momenta& p) {
  Vector3 total = Vector3::Zero();
  for (Eigen::Index i = 0; i < q.cols(); ++i) {
    Vector3 qi = Vector3::Zero();
    Vector3 pi = Vector3::Zero();
    qi.head(q.rows()) = q.col(i);
    pi.head(p.rows()) = p.col(i);
    total += qi.cross(pi);
  }
  return total;
}

Vector3 noetherPrediction(const Vector3& initial, const VariationalCoefficients& c, long step) {
  // (e^{-kappa h})^k underflows to 0 gracefully; e^{kappa t} is never formed.
  return std::pow(c.decay, static_cast<double>(step)) * initial;
}

double noetherResidual(const Vector3& value, const Vector3& prediction, const Vector3& initial) {
  return (value - prediction).norm() / std::max(initial.norm(), 1e-300);
}

}  // namespace vf
