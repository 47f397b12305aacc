#pragma once

#include <limits>
#include <string>

#include "variational_formation_core/model/formation.hpp"

namespace vf {

/// Largest frequency w = sqrt(lambda_max(Hessian of V at q)) [1/s]; 0 if no eigenvalue is > 0.
double maxStiffnessFrequency(const Formation& formation, const Positions& q);

/// Smallest non-zero frequency sqrt(lambda) of the Hessian of V at q [1/s] (eigenvalues above
/// 1e-9 of the largest): the softest shape mode; 0 if there is none.
double minStiffnessFrequency(const Formation& formation, const Positions& q);

/**
 * Linear stability limit of the variational update for a mode of frequency w (doc/maths.md §7):
 * stable iff h w < 2 cosh(kappa h / 2). Returns the smallest h > 0 with h w = 2 cosh(kappa h/2),
 * or +infinity if there is none (strong damping: every h is linearly stable).
 */
double stableTimeStepLimit(double frequency, double dampingGain);

/// Whether h w < 2 cosh(kappa h / 2).
bool isLinearlyStable(double timeStep, double frequency, double dampingGain);

/// Step-size advice at a configuration.
struct StepSizeAdvice {
  double frequency;   ///< w at the configuration [1/s]
  double limit;       ///< stableTimeStepLimit(w, kappa) [s]
  bool exceeded;      ///< h >= limit
  std::string message;  ///< empty unless exceeded: a one-line warning
};

/// Advice for step h at configurations q0 and the desired shape (the larger w of the two).
/// @param field names h in the message (the scenario field, or the flag that set it).
StepSizeAdvice adviseTimeStep(const Formation& formation, const Positions& q0, double timeStep,
                              double dampingGain, const std::string& field = "time_step");

}  // namespace vf
