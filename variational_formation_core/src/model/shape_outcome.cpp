#include "variational_formation_core/model/shape_outcome.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "variational_formation_core/model/rigid_fit.hpp"

namespace vf {

namespace {

/// Some pair outside tolerance whose distance error, falling at its current rate, is within
/// tolerance in `horizon` seconds (findShape).
bool closingWithin(const Formation& formation, const Positions& q, const Velocities& v, double scale,
                   double tolerance, double horizon) {
  const Positions& desired = formation.desiredShape();
  for (int i = 0; i < formation.agentCount(); ++i) {
    for (int j = i + 1; j < formation.agentCount(); ++j) {
      const Eigen::VectorXd a = q.col(i) - q.col(j);
      const double length = a.norm(), target = scale * (desired.col(i) - desired.col(j)).norm();
      const double error = length - target, excess = std::abs(error) - tolerance * target;
      if (excess <= 0.0 || length == 0.0) continue;
      const double falling = -(error > 0.0 ? 1.0 : -1.0) * a.dot(v.col(i) - v.col(j)) / length;  // -d|e|/dt
      if (falling * horizon >= excess) return true;
    }
  }
  return false;
}

}  // namespace

ShapeFindings findShape(const Formation& formation, const Positions& q, const Velocities& v, double scale,
                        bool congruent, double tolerance, double maxSpeed, bool withShapeError,
                        const bool* knownMirror, double horizon) {
  ShapeFindings f;
  f.shapeError = withShapeError ? formation.shapeError(q, scale) : std::numeric_limits<double>::quiet_NaN();
  f.maxEdgeError = formation.maxDistanceError(q, scale);
  f.fastestSpeed = v.cols() > 0 ? v.colwise().norm().maxCoeff() : 0.0;
  f.congruent = congruent;
  f.edgesWithin = formation.edgesWithin(q, tolerance, scale);
  f.atRest = f.fastestSpeed < restSpeed(maxSpeed) &&
             !(horizon > 0.0 && withShapeError && f.edgesWithin && !congruent &&
               closingWithin(formation, q, v, scale, tolerance, horizon));
  // A congruent shape cannot change hands without passing through a flat one, which is not
  // congruent: while it stays congruent this answer holds.
  f.mirrored = congruent && (knownMirror ? *knownMirror : isMirrorImage(q, formation.desiredShape(), tolerance));
  return f;
}

ShapeOutcome blockedShapeOutcome(ShapeOutcome outcome, const std::string& blocked) {
  outcome.verdict = ShapeVerdict::NotConverged;
  outcome.convergedStep = -1;
  outcome.blocked = blocked;
  outcome.line = "not converged (" + blocked + ")";
  return outcome;
}

bool shapeErrorMeasuredAt(long step, int agents, long lastStep) {
  const long every = static_cast<long>(std::ceil(std::pow(agents / 50.0, 2)));
  return every <= 1 || step % every == 0 || (lastStep > 0 && step == lastStep);
}

std::string verdictName(const ShapeOutcome& outcome) {
  if (!outcome.blocked.empty()) return "blocked";
  switch (outcome.verdict) {
    case ShapeVerdict::DesiredShape: return "desired_shape";
    case ShapeVerdict::MirrorImage: return "mirror_image";
    case ShapeVerdict::Folded: return "folded";
    case ShapeVerdict::StillSettling: return "still_settling";
    case ShapeVerdict::NotConverged: break;
  }
  return "not_converged";
}

ShapeOutcome shapeOutcome(const ShapeFindings& findings, long congruentSince, bool mirrorAllowed, double timeStep) {
  ShapeOutcome o;
  o.findings = findings;
  char text[200];
  if (findings.congruent && (!findings.mirrored || mirrorAllowed)) {
    o.verdict = ShapeVerdict::DesiredShape;
    o.convergedStep = congruentSince;
    std::snprintf(text, sizeof text, "converged to the desired shape at step %ld (t = %.3f s)%s", congruentSince,
                  congruentSince * timeStep, findings.mirrored ? ", its mirror image (mirror: allowed)" : "");
  } else if (findings.congruent) {
    o.verdict = ShapeVerdict::MirrorImage;
    std::snprintf(text, sizeof text,
                  "not converged: the mirror image of the desired shape from step %ld (t = %.3f s; mirror: forbidden)",
                  congruentSince, congruentSince * timeStep);
  } else if (findings.edgesWithin && findings.atRest) {
    o.verdict = ShapeVerdict::Folded;
    std::snprintf(text, sizeof text,
                  "not converged: folded, at rest with every edge within tolerance but not every pair (shape error "
                  "%.3g m)",
                  findings.shapeError);
  } else if (findings.edgesWithin) {
    o.verdict = ShapeVerdict::StillSettling;
    std::snprintf(text, sizeof text,
                  "not converged: still settling at the last step (every edge within tolerance; shape error %.3g m; "
                  "fastest agent %.3g m/s)",
                  findings.shapeError, findings.fastestSpeed);
  } else {
    std::snprintf(text, sizeof text, "not converged (final max distance error %.3g m)", findings.maxEdgeError);
  }
  o.line = text;
  return o;
}

ShapeTracker::ShapeTracker(const Formation& formation, bool mirrorAllowed, double tolerance, double maxSpeed)
    : formation_(formation),
      mirrorAllowed_(mirrorAllowed),
      tolerance_(tolerance),
      maxSpeed_(maxSpeed),
      congruence_(tolerance, maxSpeed) {}

void ShapeTracker::observe(long step, const Positions& q, const Velocities& v, double scale) {
  step_ = step;
  congruent_ = congruence_.check(formation_, q, v, scale);
  if (!congruent_) {
    congruentSince_ = -1;
  } else if (congruentSince_ < 0) {
    congruentSince_ = step;
  }
  q_ = q;
  v_ = v;
  scale_ = scale;
}

ShapeOutcome ShapeTracker::outcome(double timeStep) const {
  // Closing pairs count over the run's own duration t_k, as the monitor counts them.
  const ShapeFindings f = findShape(formation_, q_, v_, scale_, congruent_, tolerance_, maxSpeed_, true, nullptr,
                                    static_cast<double>(step_) * timeStep);
  return shapeOutcome(f, congruentSince_, mirrorAllowed_, timeStep);
}

}  // namespace vf
