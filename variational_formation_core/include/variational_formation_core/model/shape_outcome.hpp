#pragma once

#include <string>

#include "variational_formation_core/model/formation.hpp"

namespace vf {

/// What a configuration says about the shape (doc/scenarios.md, "Folded shapes and mirror images").
struct ShapeFindings {
  double shapeError = 0.0;     ///< Formation::shapeError, over all pairs [m]
  double maxEdgeError = 0.0;   ///< Formation::maxDistanceError, over the edges [m]
  double fastestSpeed = 0.0;   ///< the fastest agent's speed relative to the commanded motion [m/s]
  bool congruent = false;      ///< every pair within tolerance, every agent slow (as given)
  bool edgesWithin = false;    ///< every edge within tolerance, at any speed
  /// Every agent slower than restSpeed(maxSpeed), and no pair's distance error falling fast enough
  /// to come within tolerance in another `horizon` (findShape).
  bool atRest = false;
  bool mirrored = false;       ///< congruent, and with the mirror image of the desired shape (isMirrorImage)
};

/**
 * Below this speed [m/s] an agent is at rest: a hundredth of the congruence's speed limit
 * `maxSpeed` (0.001 m/s with the monitor's 0.1). A formation with every edge within tolerance
 * whose agents are not all at rest is still settling, not folded. Measured: at step 300 of the
 * hexagon from 30 scattered starts the runs still settling move at 0.021 to 0.032 m/s; the 67
 * folds of benchmark/deployments.py (1500 steps) below 0.00078 m/s, and the hexagon's folds
 * after 3000 steps below 1.2e-9 m/s.
 */
inline double restSpeed(double maxSpeed) { return 0.01 * maxSpeed; }

/**
 * The findings at one configuration q [m] with velocities v relative to the commanded motion
 * [m/s], against s d_ij (s = scale). `congruent` is the caller's congruence test (a
 * CongruenceTracker's, the same as congruenceSlack >= 0 with all speeds below maxSpeed). The
 * mirror test runs only on a congruent shape. O(n^2) for the shape error, O(n + |E|) without it
 * (withShapeError false: shapeError is NaN).
 * @param knownMirror the mirror test's answer at an earlier step of the same congruent stretch,
 *        taken as it is (a congruent shape cannot change hands without passing through a flat
 *        one, which is not congruent); nullptr: test it. Ignored when not congruent.
 * @param horizon [s] a formation with every edge within tolerance, not congruent and every agent
 *        slow is still not at rest while some pair outside tolerance closes fast enough to come
 *        within it in this long at its current rate, d|e_ij|/dt = sign(e_ij) (q_i - q_j).(v_i - v_j)
 *        / |q_i - q_j| (the run's own duration t_k: a distance error still falling). O(n^2), on
 *        such a formation only, with withShapeError. 0: speeds alone.
 */
ShapeFindings findShape(const Formation& formation, const Positions& q, const Velocities& v, double scale,
                        bool congruent, double tolerance, double maxSpeed, bool withShapeError = true,
                        const bool* knownMirror = nullptr, double horizon = 0.0);

/**
 * Whether a run measures the O(n^2) shape error at `step`: at most a 50-agent cost per step on
 * average (1225 pairs), so every step up to 50 agents, every ceil((n/50)^2) steps beyond, and
 * always at the last step (lastStep <= 0: unbounded). The monitor and `simulate`'s metrics use
 * this one rule. (With a 200-agent budget it was a third of a 200-agent monitor's time.)
 */
bool shapeErrorMeasuredAt(long step, int agents, long lastStep);

/**
 * The endings of a run: the desired shape (converged); its mirror image (every pair right, but
 * left and right swapped, with `mirror: forbidden`); folded (every edge within tolerance, not
 * every pair, at rest); still settling (every edge within tolerance, not in shape, still moving
 * at the last step); not converged (some edge off, or blocked). Only the first is "converged".
 */
enum class ShapeVerdict { DesiredShape, MirrorImage, Folded, StillSettling, NotConverged };

struct ShapeOutcome {
  ShapeVerdict verdict = ShapeVerdict::NotConverged;
  ShapeFindings findings;
  long convergedStep = -1;  ///< first step of the final stretch in the desired shape, -1 if none
  /// Why the run stopped short of the shape under a safety filter ("blocked: agents 2, 4",
  /// BlockedDetector::description()), or empty; set by blockedShapeOutcome.
  std::string blocked;
  /// "converged to the desired shape at step K (t = T s)", and otherwise a line starting "not
  /// converged": ": the mirror image of the desired shape from step K (t = T s; mirror:
  /// forbidden)", ": folded, at rest with every edge within tolerance but not every pair (shape
  /// error E m)", ": still settling at the last step (every edge within tolerance; shape error E m;
  /// fastest agent V m/s)" or " (final max distance error E m)".
  std::string line;
};

/// The result file's `verdict:` value: desired_shape, mirror_image, folded, still_settling or
/// not_converged, and blocked for a blockedShapeOutcome.
std::string verdictName(const ShapeOutcome& outcome);

/// The outcome of a run that the safety filter blocked: not converged, with line
/// "not converged (blocked: agents 2, 4)"; the findings are kept.
ShapeOutcome blockedShapeOutcome(ShapeOutcome outcome, const std::string& blocked);

/**
 * The verdict at the last step: the desired shape if congruent and not mirrored (or mirrored
 * with mirrorAllowed); the mirror image if congruent and mirrored without it; with every edge
 * within tolerance, folded if at rest and still settling if not; else not converged.
 * @param congruentSince first step of the congruent stretch holding at the last step (-1 if
 * none); @param timeStep h [s].
 */
ShapeOutcome shapeOutcome(const ShapeFindings& findings, long congruentSince, bool mirrorAllowed, double timeStep);

/**
 * Follows a run step by step (congruence at amortised O(n) per step, CongruenceTracker) and
 * gives its ShapeOutcome at the last observed step; `simulate`'s final line.
 */
class ShapeTracker {
 public:
  ShapeTracker(const Formation& formation, bool mirrorAllowed, double tolerance = 0.01, double maxSpeed = 0.1);
  /// Step k: q [m], v relative to the commanded motion [m/s], commanded scale s.
  void observe(long step, const Positions& q, const Velocities& v, double scale);
  /// The outcome at the last observed step. @param timeStep h [s].
  ShapeOutcome outcome(double timeStep) const;
  /// First step of the congruent stretch (either hand) holding at the last observed step, -1 if none.
  long congruentSince() const { return congruentSince_; }

 private:
  const Formation& formation_;
  bool mirrorAllowed_;
  double tolerance_, maxSpeed_;
  CongruenceTracker congruence_;
  long step_ = 0;
  long congruentSince_ = -1;
  bool congruent_ = false;
  Positions q_;
  Velocities v_;
  double scale_ = 1.0;
};

}  // namespace vf
