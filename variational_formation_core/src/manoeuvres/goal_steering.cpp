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

GoalSteering::GoalSteering(const GoalSettings& settings, double timeStep)
    : settings_(settings),
      timeStep_(timeStep),
      periodSteps_(std::max(1L, std::lround(settings.period / timeStep))),
      patienceSteps_(std::max(1L, std::lround(settings.patience / timeStep))) {}

void GoalSteering::start(const GoalPose& goal, long step) {
  goal_ = goal;
  active_ = true;
  startStep_ = progressStep_ = step;
  bestDistance_ = bestYawError_ = std::numeric_limits<double>::infinity();
  previousStep_ = -1;
  commanded_ = false;  // the first update commands whatever stands
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

SteeringStep GoalSteering::update(long step, const FormationPose& pose, bool inShape, double maxEdgeError) {
  SteeringStep s;
  if (!active_) return s;
  s.state = SteeringStep::State::Active;
  const Eigen::Vector2d toGoal = goal_.position - pose.position;
  s.distance = toGoal.norm();
  s.yawError = wrapAngle(goal_.yaw - pose.yaw);
  // Reached: within both tolerances, and settled there: moving and turning slowly, and told to
  // (what was commanded may apply only later, up to a lockstep window after it was issued).
  Eigen::Vector2d rate = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  if (previousStep_ >= 0 && step > previousStep_) {
    const double dt = static_cast<double>(step - previousStep_) * timeStep_;
    rate << (pose.position - previous_.position).norm() / dt, std::abs(wrapAngle(pose.yaw - previous_.yaw)) / dt;
  }
  previous_ = pose;
  previousStep_ = step;
  const double slowSpeed = settings_.gain * settings_.positionTolerance;
  const double slowTurn = settings_.gain * settings_.yawTolerance;
  const bool within = s.distance <= settings_.positionTolerance && std::abs(s.yawError) <= settings_.yawTolerance;
  if (within && rate(0) <= slowSpeed && rate(1) <= slowTurn && lastVelocity_.norm() <= 2.0 * slowSpeed &&
      lastAngularRate_.norm() <= 2.0 * slowTurn) {
    return finish(s, SteeringStep::State::Succeeded);
  }
  // Progress: either error down by half its tolerance since the last progress, or within both
  // tolerances and settling there (in lockstep a command applies up to a window later, so the
  // formation can sit within tolerance, still moving, for longer than the patience).
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
  if (step - progressStep_ >= patienceSteps_) {
    s.reason = "no progress for " + number(settings_.patience) + " s, " + number(s.distance) + " m and " +
               number(s.yawError) + " rad from the goal: " +
               (inShape ? std::string("the formation holds its shape but does not follow the commands (blocked?)")
                        : "the formation is not in its shape (max distance error " + number(maxEdgeError) + " m)");
    return finish(s, SteeringStep::State::Aborted);
  }
  if ((step - startStep_) % periodSteps_ != 0) return s;
  const double speed = std::min(settings_.maxSpeed, settings_.gain * s.distance);
  if (s.distance > 0.0) s.velocity.head<2>() = toGoal * (speed / s.distance);
  s.angularRate.z() = std::clamp(settings_.gain * s.yawError, -settings_.maxTurnRate, settings_.maxTurnRate);
  // A command only if it changes what the formation does: each is one more in the issued list.
  const bool changed = (s.velocity - lastVelocity_).norm() > 0.01 * settings_.maxSpeed ||
                       (s.angularRate - lastAngularRate_).norm() > 0.01 * settings_.maxTurnRate;
  if (!commanded_ || changed) {
    s.command = true;
    commanded_ = true;
    lastVelocity_ = s.velocity;
    lastAngularRate_ = s.angularRate;
  }
  return s;
}

}  // namespace vf
