#pragma once

#include <string>

#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/model/shape_outcome.hpp"

namespace vf {

/// The verdict on a run that reached its last step: it succeeded (it ran every step), unless the
/// scenario requires convergence (`require_convergence: true`) and the formation did not reach
/// the desired shape. The shape itself is the ShapeOutcome's to say (doc/scenarios.md,
/// "Requiring convergence").
struct RunVerdict {
  bool succeeded = true;
  std::string reason;  ///< why it failed (one line), empty if it succeeded
};
/// From a run's shape (`simulate`'s and the monitor's final line): only the desired shape
/// converges; a mirror image, a folded or still settling shape fails a scenario with
/// `require_convergence: true` too.
RunVerdict finishedRunVerdict(const Scenario& scenario, const ShapeOutcome& shape);

}  // namespace vf
