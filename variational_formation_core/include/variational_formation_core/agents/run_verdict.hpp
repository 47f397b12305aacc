#pragma once

#include <string>

#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/model/shape_outcome.hpp"

namespace vf {

/// Whether and when a run's formation became congruent with the desired shape, as the monitor's
/// last line and the result file say it (doc/ros_api.md, "monitor").
struct FormationOutcome {
  bool converged = false;
  double finalError = 0.0;  ///< max distance error at the last completed step [m]
  /// Why the run stopped short of the shape, "blocked: agents 2, 4" (BlockedDetector), or empty.
  std::string blocked;
  /// "converged at step K (t = T s)", "not converged (final max distance error E m)" or
  /// "not converged (blocked: agents 2, 4)".
  std::string line;
};

/**
 * @param convergedStep first step of the congruent stretch that holds at the last completed step
 * (-1: not congruent there); @param finalError the max distance error at that step [m];
 * @param timeStep h [s].
 */
FormationOutcome formationOutcome(long convergedStep, double finalError, double timeStep);
/// A run ended because the safety filter blocks the formation: @param blocked
/// BlockedDetector::description(). @param finalError [m].
FormationOutcome blockedOutcome(const std::string& blocked, double finalError);

/// The verdict on a run that reached its last step: it succeeded, unless the scenario requires
/// convergence (`require_convergence: true`) and the formation did not converge.
struct RunVerdict {
  bool succeeded = true;
  std::string reason;  ///< why it failed (one line), empty if it succeeded
};
RunVerdict finishedRunVerdict(const Scenario& scenario, const FormationOutcome& formation);
/// The same from a run's shape (`simulate`'s and the monitor's final line): converged means the
/// desired shape; a folded one fails a scenario with `require_convergence: true` too.
RunVerdict finishedRunVerdict(const Scenario& scenario, const ShapeOutcome& shape);

}  // namespace vf
