#pragma once

#include <vector>

#include "variational_formation_core/model/formation.hpp"

namespace vf {

/**
 * Companion matrix of the delayed recurrence linearised at the desired shape q*
 * (doc/delay_margin.md): with x^k = q^k - q*, H = H_diag + H_off (agent blocks on and off the
 * diagonal of the Hessian of V at q*),
 *   x^{k+1} = (1 + e^{-kappa h}) x^k - e^{-kappa h} x^{k-1} - c (H_diag x^k + H_off x^{k-D}),
 * c = 2h^2/(1 + e^{kappa h}). The state is (x^k, x^{k-1}, ..., x^{k-B+1}), B = max(2, D + 1)
 * blocks of dn rows, so the matrix is B dn x B dn.
 * @param timeStep h [s]. @param dampingGain kappa [1/s]. @param delaySteps D >= 0.
 */
Eigen::MatrixXd delayedCompanionMatrix(const Formation& formation, double timeStep,
                                       double dampingGain, long delaySteps);

/// Spectrum of one delay D, rigid-motion modes set apart.
struct DelaySpectrum {
  long delaySteps = 0;
  int fixedModes = 0;        ///< nullity of the Hessian at q*: translations, rotations (and flexes)
  int eigenvaluesAtOne = 0;  ///< companion eigenvalues within 1e-7 of 1
  double excludedDistance = 0.0;  ///< largest |lambda - 1| of the fixedModes excluded ones
  double spectralRadius = 0.0;    ///< largest |lambda| of the rest
  bool stable() const { return spectralRadius < 1.0 - 1e-9; }
};

/**
 * Eigenvalues of delayedCompanionMatrix (Eigen::EigenSolver, no eigenvectors). The fixedModes
 * eigenvalues closest to 1 are the rigid motions (x^k = r for all k with H r = 0); they are
 * excluded and the spectral radius of the rest is returned.
 */
DelaySpectrum delaySpectrum(const Formation& formation, double timeStep, double dampingGain,
                            long delaySteps);

/**
 * Number of roots of the characteristic polynomial chi_D(lambda) = det(lambda^{D-1}(lambda - 1)
 * (lambda - e^{-kappa h}) I + c lambda^D H_diag + c H_off) (D >= 1; D = 0: lambda ((lambda - 1)
 * (lambda - e^{-kappa h}) I + c lambda H)) outside the closed unit disk, the fixed modes at 1
 * set apart, by the argument principle on the unit circle (doc/delay_margin.md): it costs a dn x dn
 * complex LU per frequency instead of an eigensolve of size B dn. -1 if the count is unreliable
 * (kappa = 0: the fixed modes are not simple).
 */
int unstableRootCount(const Formation& formation, double timeStep, double dampingGain,
                      long delaySteps);

/// The predicted delay margin.
struct DelayMargin {
  /// Largest D such that every D' in 0..D is locally stable; -1 if D = 0 is not;
  /// maxDelay if no instability was found up to maxDelay (see capped).
  long margin = -1;
  bool capped = false;
  std::vector<int> unstableRoots;     ///< unstableRootCount for D = 0, 1, ... as scanned
  double scanSeconds = 0.0;           ///< wall time of that scan
  /// Companion-matrix check at D* and D* + 1 (those whose matrix has <= maxCompanionSize rows).
  std::vector<DelaySpectrum> checks;
  double checkSeconds = 0.0;
  /// Every check agrees with the scan (stable at D*, unstable at D* + 1).
  bool confirmed() const;
};

/**
 * Scans D = 0, 1, ..., maxDelay upward with unstableRootCount and stops at the first unstable D,
 * then checks D* and D* + 1 with the companion matrix's eigenvalues.
 * @throws InvalidInput if the formation has no edges (no neighbours, nothing is delayed).
 */
DelayMargin predictDelayMargin(const Formation& formation, double timeStep, double dampingGain,
                               long maxDelay, long maxCompanionSize = 1200);

}  // namespace vf
