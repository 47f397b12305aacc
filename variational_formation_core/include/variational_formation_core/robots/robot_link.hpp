#pragma once

#include <string>
#include <vector>

#include "variational_formation_core/robots/unicycle_command.hpp"
#include "variational_formation_core/robots/robot_mode.hpp"

namespace vf {

/// How a robot-mode agent is tied to its robot (doc/robots.md); the robot-mode agent's parameters.
struct RobotLinkSettings {
  RobotKinematics kinematics = RobotKinematics::Holonomic;
  RobotFeedback feedback = RobotFeedback::Integrated;
  HandPointSettings hand;       ///< unicycle: hand_offset, max_speed, max_turn_rate
  double lag = 0.1;             ///< robot_lag: the robot's assumed lag tau [s] >= 0
  double correctionTime = 5.0;  ///< correction_time Tc [s] >= 0 of integrated feedback
  double trackingGain = -1.0;   ///< tracking_gain k_p [1/s]; < 0: 1 / (4 (lag + h))
};

/// "holonomic" or "unicycle". @throws InvalidInput "kinematics: ..." naming the accepted words.
RobotKinematics parseKinematics(const std::string& word);
/// "integrated" or "odometry". @throws InvalidInput "feedback: ...".
RobotFeedback parseFeedback(const std::string& word);
const char* kinematicsName(RobotKinematics kinematics);
const char* feedbackName(RobotFeedback feedback);

/**
 * The point of a robot that the formation controls, from an odometry pose: position (x, y, z)
 * [m], orientation quaternion (qx, qy, qz, qw). Holonomic: the position (z only in 3D); unicycle:
 * the hand point handOffset [m] ahead of the axle at the quaternion's yaw (hand_point.hpp).
 * Writes `dimension` values to `point` only once every number passed its check.
 * @return the planar pose (its heading is a unicycle's).
 * @throws InvalidInput "odometry: ..." on a non-finite value or a quaternion whose norm is not 1
 * (within kQuaternionNormTolerance).
 */
PlanarPose pointFromOdometry(RobotKinematics kinematics, double handOffset, int dimension, double x, double y,
                             double z, double qx, double qy, double qz, double qw, double* point);

/**
 * The agent's side of robot mode, without a transport: what the agent makes of its robot's
 * odometry and what it sends back. One per robot-mode agent (TimedAgentNode); runRobotLoop runs
 * the same class against simulated robots.
 *
 * - The measured point is the odometry position (holonomic) or the hand point l ahead of the axle
 *   at the odometry heading (unicycle, hand_point.hpp).
 * - The tick starts from startPosition: the measured point (odometry feedback) or the agent's own
 *   integrated position pulled towards it with time constant Tc (integrated feedback,
 *   correctedPosition).
 * - The command after the tick is the agent's velocity v_k (odometry feedback), or v_k + k_p (q_k
 *   - measured) (integrated feedback: the robot tracks where the formation puts it, with v_k as
 *   feed-forward); for a unicycle it becomes (linear.x, angular.z) at the measured heading, scaled
 *   down to the limits.
 */
class RobotLink {
 public:
  /// The robot's velocity command: cmd_vel linear (x, y, z) and angular.z.
  struct Command {
    double linear[3] = {0.0, 0.0, 0.0};
    double angular = 0.0;
    bool saturated = false;  ///< unicycle limits scaled it down
  };

  /**
   * @param dimension 2 or 3 (a unicycle needs 2). @param timeStep h [s] > 0.
   * @throws InvalidInput naming the parameter (hand_offset, max_speed, max_turn_rate, robot_lag,
   * correction_time, tracking_gain, kinematics).
   */
  RobotLink(const RobotLinkSettings& settings, int dimension, double timeStep);

  /**
   * An odometry pose: position (x, y, z) [m], orientation quaternion (qx, qy, qz, qw). z is ignored
   * in 2D; the yaw gives the heading of a unicycle.
   * @throws InvalidInput "odometry: ..." on a non-finite value or a quaternion whose norm is not 1
   * (within kQuaternionNormTolerance); the measurement is then unchanged.
   */
  void measureOdometry(double x, double y, double z, double qx, double qy, double qz, double qw);
  /// A unicycle's measured axle pose (simulations): the hand point and heading from it.
  void measurePose(const PlanarPose& pose);
  /// A holonomic robot's measured position, d values (simulations).
  void measurePoint(const std::vector<double>& point);

  bool measured() const { return measured_; }
  /// The measured point [m] (the hand point for a unicycle), d values.
  const std::vector<double>& measuredPoint() const { return point_; }
  /// The measured heading [rad] (unicycle), 0 for a holonomic robot.
  double heading() const { return heading_; }

  /// The position the agent's next tick starts from (see the class comment), into `out`.
  /// @throws InvalidInput before any measurement.
  void startPosition(const std::vector<double>& integrated, std::vector<double>& out) const;

  /**
   * The command after a tick: `velocity` is v_k, `target` is q_k (where the robot should be now,
   * the position the tick started from). Counts saturated commands.
   */
  Command command(const std::vector<double>& velocity, const std::vector<double>& target);

  const RobotLinkSettings& settings() const { return settings_; }
  /// k_p [1/s] in use (integrated feedback).
  double trackingGain() const { return trackingGain_; }
  long saturatedCommands() const { return saturated_; }
  long commands() const { return commands_; }

 private:
  RobotLinkSettings settings_;
  int dimension_;
  double timeStep_;
  double trackingGain_;
  bool measured_ = false;
  std::vector<double> point_;
  double heading_ = 0.0;
  long saturated_ = 0;
  long commands_ = 0;
};

}  // namespace vf
