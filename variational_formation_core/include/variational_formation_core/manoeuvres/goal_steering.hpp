#pragma once

#include <string>

#include "variational_formation_core/common/types.hpp"

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

/// How a goal is steered (the monitor's ~goal_* parameters, doc/ros_api.md).
struct GoalSettings {
  double maxSpeed = 0.5;           ///< |v*| at most [m/s] > 0
  double maxTurnRate = 0.3;        ///< |omega*| at most [rad/s] > 0
  /// v* = gain x distance, omega* = gain x heading error, then limited [1/s] > 0. 0.5: in lockstep
  /// a command applies up to ~window steps (1 s at h = 0.01) after the step it was computed from.
  double gain = 0.5;
  double positionTolerance = 0.05; ///< the goal is reached within this distance [m] > 0
  double yawTolerance = 0.05;      ///< and this heading error [rad] > 0
  double patience = 5.0;           ///< aborted after this long without progress [s] > 0
  double period = 0.2;             ///< a new command at most this often [s] > 0
};

/// Every field positive and finite. @throws InvalidInput naming the monitor parameter (~goal_*).
void validateGoalSettings(const GoalSettings& settings);

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
 * commanded motions (v*, omega*): v* points at the goal with |v*| = min(maxSpeed, gain x
 * distance), omega*_z = gain x heading error limited to maxTurnRate. The centroid moves with v*
 * and the shape turns about it with omega*, so the two converge independently.
 *
 * A new command at most every `period` (counted in steps from the goal's start, so a lockstep
 * run decides at the same steps every time), and only if it differs from the last by more than
 * 1 % of a limit; reaching the goal or aborting issues the stop (0, 0). Reached: within both
 * tolerances, moving and turning at most gain x tolerance (from the last two updates), and the
 * standing command at most twice that (a command may apply only a lockstep window after it was
 * issued: the formation must not be about to leave).
 * Progress: the distance or the heading error improving by half its tolerance; none for
 * `patience` aborts, with the distance left and whether the formation holds its shape.
 */
class GoalSteering {
 public:
  /// @param settings validated; @param timeStep h [s] > 0.
  GoalSteering(const GoalSettings& settings, double timeStep);

  /// Starts (or replaces) the goal at `step`; the next update commands at once.
  void start(const GoalPose& goal, long step);
  /// Forgets the goal (cancelled, pre-empted, the run ended). @return whether one was active
  /// (the formation then needs the stop command, stopCommand()).
  bool stop();
  bool active() const { return active_; }
  const GoalPose& goal() const { return goal_; }

  /**
   * Step `step` measured: the formation at `pose`, `inShape` (congruent with the desired shape)
   * and `maxEdgeError` [m] (for the reason). Idle without an active goal.
   */
  SteeringStep update(long step, const FormationPose& pose, bool inShape, double maxEdgeError);

 private:
  SteeringStep finish(SteeringStep s, SteeringStep::State state);

  GoalSettings settings_;
  double timeStep_;
  long periodSteps_, patienceSteps_;
  bool active_ = false;
  GoalPose goal_;
  long startStep_ = 0, progressStep_ = 0;
  double bestDistance_ = 0.0, bestYawError_ = 0.0;
  FormationPose previous_;  // at previousStep_ (-1: none since the start)
  long previousStep_ = -1;
  bool commanded_ = false;  // a command of this steering is standing (not the stop)
  Vector3 lastVelocity_ = Vector3::Zero(), lastAngularRate_ = Vector3::Zero();
};

}  // namespace vf
