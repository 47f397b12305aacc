#pragma once

#include <string>

#include "variational_formation_core/common/types.hpp"
#include "variational_formation_core/manoeuvres/command_schedule.hpp"

namespace vf {

/// A goal pose on the ground plane (rviz's "2D Nav Goal", move_base_msgs/MoveBase): where the
/// formation's centroid should go and which way its desired shape should face.
struct GoalPose {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< x, y in the world frame [m]
  double yaw = 0.0;                                    ///< about z, in (-pi, pi] [rad]
};

/// Where the formation is: its centroid and its heading (FormationPose, formationPose).
struct FormationPose {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< centroid x, y [m]
  double yaw = 0.0;  ///< rotation about z that best maps the desired shape onto q [rad]
};

/**
 * The goal pose of a message: position (x, y) and the yaw of the quaternion (x, y, z, w).
 * The quaternion must be finite and of norm within 1e-3 of 1 (what rviz and tf send; a zero
 * quaternion, rostopic's default, is refused).
 * @throws InvalidInput naming `field` (e.g. "goal.target_pose.pose") and the value.
 */
GoalPose goalPose(double x, double y, double qx, double qy, double qz, double qw, const std::string& field);

/**
 * The centroid of q (x, y) and the yaw of the rotation R that best maps the desired shape q*
 * onto q (fitRigidMotion without reflection; yaw = atan2(R_10, R_00)): 0 when the formation
 * stands as in the scenario's `desired_position`. Scale-free. @param q, desired d x n [m].
 */
FormationPose formationPose(const Positions& q, const Positions& desired);

/// The wrap of an angle to (-pi, pi] [rad].
double wrapAngle(double angle);

/// How a goal is steered (the monitor's ~goal_* parameters, doc/ros_api.md). Every time is in
/// seconds of simulated time, never in steps: the same settings steer alike at any h and window.
struct GoalSettings {
  double maxSpeed = 0.5;           ///< |v*| at most [m/s] > 0
  double maxTurnRate = 0.3;        ///< |omega*| at most [rad/s] > 0
  /// v* = gain x (goal - predicted position), omega* = gain x predicted heading error, then
  /// limited [1/s] > 0; lowered to kappa / 4 and to 1 / (period + the gap between two apply
  /// steps) where those are smaller.
  double gain = 0.5;
  double positionTolerance = 0.05; ///< the goal is reached within this distance [m] > 0
  double yawTolerance = 0.05;      ///< and this heading error [rad] > 0
  double patience = 5.0;           ///< aborted after this long without progress, beyond the command latency [s] > 0
  double period = 0.2;             ///< a new command at most this often [s] > 0
};

/// Every field positive and finite. @throws InvalidInput naming the monitor parameter (~goal_*).
void validateGoalSettings(const GoalSettings& settings);

/// One completed step as the steering sees it.
struct GoalObservation {
  long step = 0;               ///< the completed step measured
  FormationPose pose;          ///< the formation there
  bool inShape = true;         ///< congruent with the desired shape
  double maxEdgeError = 0.0;   ///< [m], for an abort's reason
  bool constrained = false;    ///< a safety constraint bound at this step (only then is it "blocked")
  /// The step from which a command offered now applies (> step): in lockstep the allowed step, up
  /// to ~window steps ahead; step + 1 where commands go out at once. -1: none can be issued now
  /// (one already applies from the allowed step).
  long applyStep = -1;
};

/// What the steering says at one step.
struct SteeringStep {
  enum class State { Idle, Active, Succeeded, Aborted };
  State state = State::Idle;
  bool command = false;                         ///< offer (velocity, angularRate) now
  Vector3 velocity = Vector3::Zero();           ///< v* [m/s] (z = 0)
  Vector3 angularRate = Vector3::Zero();        ///< omega* [rad/s] (z only)
  double distance = 0.0;                        ///< centroid to goal [m]
  double yawError = 0.0;                        ///< goal yaw - heading, wrapped [rad]
  std::string reason;                           ///< why it was aborted (one line), else empty
};

/**
 * Steers a formation's centroid to a goal position and its heading to the goal's yaw through
 * commanded motions (v*, omega*), whatever the latency between the step a command is computed
 * from and the step it applies from (doc/manoeuvres.md, "Goals: why they settle").
 *
 * Prediction: from the measured pose and velocity, the formation follows the commands in force
 * (the schedule the agents apply) up to the apply step a, each with the update's own lag
 * (velocity u <- e^{-kappa h} u + (1 - e^{-kappa h}) v* per step). The command is computed from
 * that predicted pose, so the latency drops out of the loop: v* points at the goal with
 * |v*| = min(maxSpeed, g x predicted distance), omega*_z = g x predicted heading error limited
 * to maxTurnRate, g = min(gain, kappa / 4, 1 / dT), dT the longest a command stands before the
 * next applies (`period` plus the gap between apply steps): the loop left,
 * c'' = -kappa c' + kappa g (goal - c), has real roots, and from one command to the next the error
 * shrinks by a factor 1 - g dT in [0, 1).
 *
 * A new command only at a new apply step, `period` after the last, and only if it differs by
 * more than 1 % of a limit. Reached: within both tolerances now, and at rest within them too if
 * the stop applies at a (predicted, lag included); it issues the stop (0, 0).
 * Progress: the distance or the heading error improving by half its tolerance (or within both
 * tolerances); none for `patience` beyond the latency of the last command aborts, saying how far
 * it is and why: the safety filter bound (blocked), or the shape is lost, or neither.
 */
class GoalSteering {
 public:
  /// @param settings validated; @param timeStep h [s] > 0; @param dampingGain kappa [1/s] >= 0.
  GoalSteering(const GoalSettings& settings, double timeStep, double dampingGain);

  /**
   * Refuses a goal that cannot be reached: farther from `from` than maxSpeed covers in
   * `secondsLeft` (the run's time left; infinity for an unbounded run), so far out that a double
   * cannot resolve the position tolerance there, or any goal without damping (kappa = 0).
   * @throws InvalidInput naming `field` (e.g. "goal.target_pose.pose.position"), the value and why.
   */
  void checkReachable(const GoalPose& goal, const FormationPose& from, double secondsLeft,
                      const std::string& field) const;
  /// Starts (or replaces) the goal at `step`; the next update that can issue commands at once.
  void start(const GoalPose& goal, long step);
  /// Forgets the goal (cancelled, pre-empted, the run ended). @return whether one was active
  /// (the formation then needs the stop command).
  bool stop();
  bool active() const { return active_; }
  const GoalPose& goal() const { return goal_; }

  /// Step `seen.step` measured, under the commands `inForce` (the schedule the agents apply:
  /// the scenario's with every issued command). Idle without an active goal.
  SteeringStep update(const GoalObservation& seen, const CommandSchedule& inForce);

 private:
  /// Where the formation comes to rest if the stop applies from seen.applyStep (the commands in
  /// force until then, each followed with the update's lag); `at` the pose at that step.
  FormationPose predictRest(const GoalObservation& seen, const CommandSchedule& inForce, FormationPose& at) const;
  SteeringStep finish(SteeringStep s, SteeringStep::State state);
  std::string abortReason(const SteeringStep& s, const GoalObservation& seen) const;

  GoalSettings settings_;
  double timeStep_, dampingGain_, lag_;  // lag_ = e^{-kappa h}
  long periodSteps_, patienceSteps_;
  bool active_ = false;
  GoalPose goal_;
  long startStep_ = 0, progressStep_ = 0, constrainedStep_ = -1;
  double bestDistance_ = 0.0, bestYawError_ = 0.0;
  FormationPose previous_;  // at previousStep_ (-1: none since the start)
  long previousStep_ = -1;
  long applyStep_ = -1, decidedStep_ = -1;  // the last command's apply and decision steps
  long latencySteps_ = 0;                   // the longest apply step - measured step seen
  long seenApplyStep_ = -1, applyGap_ = 0;  // the newest apply step seen, and its gap to the one before
  bool commanded_ = false;  // a command of this steering is standing (not the stop)
  Vector3 lastVelocity_ = Vector3::Zero(), lastAngularRate_ = Vector3::Zero();
};

}  // namespace vf
