#include "variational_formation_core/agents/run_verdict.hpp"

#include <cstdio>

namespace vf {

namespace {

/// Why the shape is not the desired one, in a few words.
std::string shortfall(const ShapeOutcome& shape) {
  if (!shape.blocked.empty()) return shape.blocked;
  char text[80];
  switch (shape.verdict) {
    case ShapeVerdict::MirrorImage: return "its mirror image";
    case ShapeVerdict::Folded: return "folded";
    case ShapeVerdict::StillSettling: return "still settling at the last step";
    case ShapeVerdict::DesiredShape:
    case ShapeVerdict::NotConverged: break;
  }
  std::snprintf(text, sizeof text, "final max distance error %.3g m", shape.findings.maxEdgeError);
  return text;
}

}  // namespace

RunVerdict finishedRunVerdict(const Scenario& scenario, const ShapeOutcome& shape) {
  RunVerdict v;
  if (scenario.requireConvergence && shape.verdict != ShapeVerdict::DesiredShape) {
    v.succeeded = false;
    v.reason = "the formation did not converge (" + shortfall(shape) +
               "), and the scenario requires it (require_convergence: true)";
  }
  return v;
}

}  // namespace vf
