#include "variational_formation_core/agents/run_verdict.hpp"

#include <cstdio>

namespace vf {

FormationOutcome formationOutcome(long convergedStep, double finalError, double timeStep) {
  FormationOutcome o;
  char text[160];
  o.converged = convergedStep >= 0;
  o.finalError = finalError;
  if (o.converged) {
    std::snprintf(text, sizeof text, "converged at step %ld (t = %.3f s)", convergedStep, convergedStep * timeStep);
  } else {
    std::snprintf(text, sizeof text, "not converged (final max distance error %.3g m)", finalError);
  }
  o.line = text;
  return o;
}

FormationOutcome blockedOutcome(const std::string& blocked, double finalError) {
  FormationOutcome o;
  o.finalError = finalError;
  o.blocked = blocked;
  o.line = "not converged (" + blocked + ")";
  return o;
}

RunVerdict finishedRunVerdict(const Scenario& scenario, const FormationOutcome& formation) {
  RunVerdict v;
  if (scenario.requireConvergence && !formation.converged) {
    v.succeeded = false;
    if (!formation.blocked.empty()) {
      v.reason = "the formation did not converge (" + formation.blocked +
                 "), and the scenario requires it (require_convergence: true)";
      return v;
    }
    char text[200];
    std::snprintf(text, sizeof text,
                  "the formation did not converge (final max distance error %.3g m), and the scenario requires it "
                  "(require_convergence: true)",
                  formation.finalError);
    v.reason = text;
  }
  return v;
}

RunVerdict finishedRunVerdict(const Scenario& scenario, const ShapeOutcome& shape) {
  if (shape.verdict == ShapeVerdict::NotConverged) {
    if (!shape.blocked.empty()) return finishedRunVerdict(scenario, blockedOutcome(shape.blocked, shape.findings.maxEdgeError));
    return finishedRunVerdict(scenario, formationOutcome(-1, shape.findings.maxEdgeError, scenario.timeStep));
  }
  RunVerdict v;
  if (scenario.requireConvergence && shape.verdict != ShapeVerdict::DesiredShape) {
    v.succeeded = false;
    v.reason = "the formation did not reach the desired shape, and the scenario requires it (require_convergence: true)";
  }
  return v;
}

}  // namespace vf
