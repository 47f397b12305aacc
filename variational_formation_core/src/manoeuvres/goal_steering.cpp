#include "variational_formation_core/manoeuvres/goal_steering.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/model/rigid_fit.hpp"

namespace vf {

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string number(double x) { return formatRounded(x); }

}  // namespace

double wrapAngle(double angle) {
  const double wrapped = std::remainder(angle, 2.0 * kPi);  // in [-pi, pi]
  return wrapped <= -kPi ? wrapped + 2.0 * kPi : wrapped;
}

GoalPose goalPose(double x, double y, double qx, double qy, double qz, double qw, const std::string& field) {
  if (!std::isfinite(x) || !std::isfinite(y)) {
    throw InvalidInput(field + ".position: must be finite, got (" + number(x) + ", " + number(y) + ")");
  }
  const double norm = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
  if (!(std::abs(norm - 1.0) <= 1e-3)) {
    throw InvalidInput(field + ".orientation: must be a unit quaternion, got (" + number(qx) + ", " + number(qy) +
                       ", " + number(qz) + ", " + number(qw) + ") of norm " + number(norm));
  }
  GoalPose g;
  g.position << x, y;
  // The rotation's heading: where it takes the x axis, projected on the ground plane.
  g.yaw = wrapAngle(std::atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz)));
  return g;
}

FormationPose formationPose(const Positions& q, const Positions& desired) {
  FormationPose p;
  const Eigen::VectorXd c = q.rowwise().mean();
  p.position << c(0), c(1);
  const RigidFit fit = fitRigidMotion(q, desired, /*allowReflection=*/false);
  p.yaw = std::atan2(fit.rotation(1, 0), fit.rotation(0, 0));
  return p;
}

void validateGoalSettings(const GoalSettings& s) {
  requireFiniteAbove("~goal_max_speed", s.maxSpeed, 0.0, "m/s");
  requireFiniteAbove("~goal_max_turn_rate", s.maxTurnRate, 0.0, "rad/s");
  requireFiniteAbove("~goal_gain", s.gain, 0.0, "1/s");
  requireFiniteAbove("~goal_tolerance", s.positionTolerance, 0.0, "m");
  requireFiniteAbove("~goal_yaw_tolerance", s.yawTolerance, 0.0, "rad");
  requireFiniteAbove("~goal_patience", s.patience, 0.0, "s");
  requireFiniteAbove("~goal_period", s.period, 0.0, "s");
}

GoalSteering::GoalSteering(const GoalSettings& settings, double timeStep, double dampingGain)
    : settings_(settings),
      timeStep_(timeStep),
      dampingGain_(dampingGain),
      lag_(std::exp(-dampingGain * timeStep)),  // doc/maths.md §2: e^{-kappa h}, never e^{kappa t}
      periodSteps_(std::max(1L, std::lround(settings.period / timeStep))),
      patienceSteps_(std::max(1L, std::lround(settings.patience / timeStep))) {}

void GoalSteering::checkReachable(const GoalPose& goal, const FormationPose& from, double secondsLeft,
                                  const std::string& field) const {
  if (!(dampingGain_ > 0.0)) {
    throw InvalidInput(field + ": no goal can be reached with kappa = " + number(dampingGain_) +
                       ": the damping is what tracks a commanded motion");
  }
  const std::string where = "(" + number(goal.position.x()) + ", " + number(goal.position.y()) + ")";
  const double distance = std::hypot(goal.position.x() - from.position.x(), goal.position.y() - from.position.y());
  const double needs = distance / settings_.maxSpeed;
  if (needs > secondsLeft) {
    throw InvalidInput(field + ": " + where + " is " + number(distance) + " m from the centroid: at ~goal_max_speed " +
                       number(settings_.maxSpeed) + " m/s that takes at least " + number(needs) +
                       " s, and the run ends in " + number(secondsLeft) + " s");
  }
  const double far = std::max(std::abs(goal.position.x()), std::abs(goal.position.y()));
  const double spacing = std::nextafter(far, std::numeric_limits<double>::infinity()) - far;
  if (spacing > 1e-3 * settings_.positionTolerance) {
    throw InvalidInput(field + ": " + where + " is too far out: doubles there are " + number(spacing) +
                       " m apart, too coarse for ~goal_tolerance " + number(settings_.positionTolerance) + " m");
  }
}

void GoalSteering::start(const GoalPose& goal, long step) {
  goal_ = goal;
  active_ = true;
  startStep_ = progressStep_ = step;
  constrainedStep_ = -1;
  bestDistance_ = bestYawError_ = std::numeric_limits<double>::infinity();
  previousStep_ = -1;
  applyStep_ = decidedStep_ = -1;
  latencySteps_ = 0;
  commanded_ = false;  // the first update that can issue commands whatever stands
}

bool GoalSteering::stop() {
  const bool was = active_;
  active_ = false;
  return was;
}

SteeringStep GoalSteering::finish(SteeringStep s, SteeringStep::State state) {
  s.state = state;
  s.command = true;  // the stop
  s.velocity.setZero();
  s.angularRate.setZero();
  active_ = false;
  commanded_ = false;
  return s;
}

FormationPose GoalSteering::predictRest(const GoalObservation& seen, const CommandSchedule& inForce,
                                        FormationPose& at) const {
  // The velocity of interval step - 1 (measured), or that of the command in force (none yet).
  Eigen::Vector2d u = inForce.at(seen.step - 1).velocity.head<2>();
  double turn = inForce.at(seen.step - 1).angularRate.z();
  if (previousStep_ >= 0 && seen.step > previousStep_) {
    const double dt = static_cast<double>(seen.step - previousStep_) * timeStep_;
    u = (seen.pose.position - previous_.position) / dt;
    turn = wrapAngle(seen.pose.yaw - previous_.yaw) / dt;
  }
  // Each interval's velocity follows the command with the update's damping (doc/maths.md §9.2: the
  // centroid obeys c'' = -kappa (c' - v*)); the latency is only known commands being followed.
  at = seen.pose;
  for (long k = seen.step; k < seen.applyStep; ++k) {
    const Command& c = inForce.at(k);
    u = lag_ * u + (1.0 - lag_) * c.velocity.head<2>();
    turn = lag_ * turn + (1.0 - lag_) * c.angularRate.z();
    at.position += timeStep_ * u;
    at.yaw += timeStep_ * turn;
  }
  // After the stop: h (a + a^2 + ...) times the last velocity; without damping, no rest.
  const double coast = lag_ < 1.0 ? timeStep_ * lag_ / (1.0 - lag_) : std::numeric_limits<double>::infinity();
  FormationPose rest = at;
  if (u.norm() > 0.0) rest.position += coast * u;
  if (turn != 0.0) rest.yaw += coast * turn;
  return rest;
}

std::string GoalSteering::abortReason(const SteeringStep& s, const GoalObservation& seen) const {
  const std::string shape =
      seen.inShape ? std::string() : " (max distance error " + number(seen.maxEdgeError) + " m)";
  std::string why;
  if (constrainedStep_ >= progressStep_) {
    why = "the safety filter binds and the formation does not get closer: blocked" + shape;
  } else if (seen.inShape) {
    why = "the formation holds its shape and no safety constraint binds, but it does not follow the commands";
  } else {
    why = "the formation is not in its shape" + shape;
  }
  return "no progress for " + number(settings_.patience) + " s, " + number(s.distance) + " m and " +
         number(s.yawError) + " rad from the goal: " + why;
}

SteeringStep GoalSteering::update(const GoalObservation& seen, const CommandSchedule& inForce) {
  SteeringStep s;
  if (!active_) return s;
  s.state = SteeringStep::State::Active;
  const long step = seen.step;
  const Eigen::Vector2d toGoal = goal_.position - seen.pose.position;
  s.distance = toGoal.norm();
  s.yawError = wrapAngle(goal_.yaw - seen.pose.yaw);
  if (seen.constrained) constrainedStep_ = step;
  const bool canIssue = seen.applyStep > step;
  if (canIssue) latencySteps_ = std::max(latencySteps_, seen.applyStep - step);
  if (canIssue && seen.applyStep > seenApplyStep_) {  // a new apply step: how far from the last one
    if (seenApplyStep_ >= 0) applyGap_ = seen.applyStep - seenApplyStep_;
    seenApplyStep_ = seen.applyStep;
  }
  const bool within = s.distance <= settings_.positionTolerance && std::abs(s.yawError) <= settings_.yawTolerance;
  const bool decide = canIssue && seen.applyStep > applyStep_ && (!commanded_ || step - decidedStep_ >= periodSteps_);
  FormationPose at;
  const FormationPose rest = (within && canIssue) || decide ? predictRest(seen, inForce, at) : FormationPose();
  previous_ = seen.pose;
  previousStep_ = step;
  // Reached: there now, and still there once the stop (applying from the apply step) has brought
  // the formation to rest.
  if (within && canIssue && (goal_.position - rest.position).norm() <= settings_.positionTolerance &&
      std::abs(wrapAngle(goal_.yaw - rest.yaw)) <= settings_.yawTolerance) {
    return finish(s, SteeringStep::State::Succeeded);
  }
  // Progress: either error down by half its tolerance since the last progress, or within both
  // tolerances (settling there). None for the patience, counted once the commands can act.
  bool progressed = within;
  if (s.distance <= bestDistance_ - 0.5 * settings_.positionTolerance) {
    bestDistance_ = s.distance;
    progressed = true;
  }
  if (std::abs(s.yawError) <= bestYawError_ - 0.5 * settings_.yawTolerance) {
    bestYawError_ = std::abs(s.yawError);
    progressed = true;
  }
  if (progressed) progressStep_ = step;
  if (step - progressStep_ >= patienceSteps_ + latencySteps_) {
    s.reason = abortReason(s, seen);
    return finish(s, SteeringStep::State::Aborted);
  }
  if (!decide) return s;
  // The gain: at most 1 / dT, dT the longest this command can stand before the next applies (the
  // period, then the next apply step), and at most kappa / 4 (real roots of s^2 + kappa s + kappa g).
  const double standing = static_cast<double>(periodSteps_ + applyGap_) * timeStep_;
  const double gain = std::min({settings_.gain, 1.0 / standing, dampingGain_ / 4.0});
  const Eigen::Vector2d ahead = goal_.position - at.position;
  const double distance = ahead.norm(), yawError = wrapAngle(goal_.yaw - at.yaw);
  const double speed = std::min(settings_.maxSpeed, gain * distance);
  if (distance > 0.0) s.velocity.head<2>() = ahead * (speed / distance);
  s.angularRate.z() = std::clamp(gain * yawError, -settings_.maxTurnRate, settings_.maxTurnRate);
  // A command only if it changes what the formation does: each is one more in the issued list.
  const bool changed = (s.velocity - lastVelocity_).norm() > 0.01 * settings_.maxSpeed ||
                       (s.angularRate - lastAngularRate_).norm() > 0.01 * settings_.maxTurnRate;
  if (!commanded_ || changed) {
    s.command = true;
    commanded_ = true;
    applyStep_ = seen.applyStep;
    decidedStep_ = step;
    lastVelocity_ = s.velocity;
    lastAngularRate_ = s.angularRate;
  }
  return s;
}

}  // namespace vf
