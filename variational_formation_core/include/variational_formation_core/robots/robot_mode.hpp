#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "variational_formation_core/model/scenario.hpp"

namespace vf {

/// The robots of a closed-loop run.
enum class RobotKinematics { Holonomic, Unicycle };

/// Where the agents' positions come from: the odometry at every tick, or their own integration
/// corrected slowly towards the odometry.
enum class RobotFeedback { Odometry, Integrated };

/// The scenario's delay margin against a robot's lag plus one tick (doc/robots.md).
struct RobotLagCheck {
  long marginSteps = -1;       ///< D* (predictDelayMargin); -1 if not even D = 0 is stable
  bool capped = false;         ///< no instability found up to the delays that matter
  double marginSeconds = 0.0;  ///< D* h [s]
  double lagPlusTick = 0.0;    ///< lag + tick period [s]
  bool exceeded = false;       ///< lagPlusTick > marginSeconds, whatever the feedback
  bool applies = true;         ///< odometry feedback: the margin bounds the lag
  std::string warning;         ///< one line if it applies and is exceeded, else empty
  std::string info;            ///< one line otherwise: the numbers, and whether they matter
};

/**
 * Predicts the delay margin D* of the scenario's formation at its kappa and h and compares D* h
 * with lag + tickPeriod, the staleness a robot's first-order lag adds to the agent's own position
 * in odometry feedback. With integrated feedback the lag reaches the formation only through the
 * slow correction, so the margin does not bound it: the numbers go to `info`, never `warning`.
 * The robot-mode agent logs `warning` (or `info`) at start. The lines name the options they
 * concern: robot_lag, feedback and correction_time, after `optionPrefix` ("~" for a node).
 * Numbers are rounded (formatRounded).
 * @param lag robot lag tau [s] >= 0. @param tickPeriod [s] > 0.
 * @throws InvalidInput on bad numbers or a formation without edges.
 */
RobotLagCheck checkRobotLag(const Scenario& scenario, double lag, double tickPeriod,
                            RobotFeedback feedback = RobotFeedback::Odometry, const std::string& optionPrefix = "");

/**
 * Integrated feedback (doc/robots.md): the position the agent's next tick starts from, its own
 * integrated position pulled towards the odometry with time constant correctionTime Tc:
 * q + (1 - e^{-h/Tc}) (measured - q). Tc = 0 gives the measurement (odometry feedback).
 * Written to `out` (d values).
 * @throws InvalidInput on Tc < 0, h <= 0 or non-finite values.
 */
void correctedPosition(const std::vector<double>& integrated, const std::vector<double>& measured,
                       double timeStep, double correctionTime, std::vector<double>& out);

struct RobotLoopSettings {
  RobotKinematics kinematics = RobotKinematics::Holonomic;
  RobotFeedback feedback = RobotFeedback::Integrated;
  double lag = 0.1;              ///< robots' tau [s]
  double odometryNoise = 0.01;   ///< [m]
  double headingNoise = 0.01;    ///< [rad], unicycle only
  double maxSpeed = 2.0;         ///< [m/s]
  double maxAcceleration = 20.0; ///< [m/s^2], holonomic only
  double maxTurnRate = 4.0;      ///< [rad/s], unicycle only
  double handOffset = 0.1;       ///< [m], unicycle only
  double correctionTime = 5.0;   ///< Tc [s] of integrated feedback
  double trackingGain = -1.0;    ///< k_p [1/s] of integrated feedback; < 0: 1/(4 (lag + h))
  std::uint64_t seed = 1;        ///< odometry noise (robot i uses seed + i)
  std::uint64_t headingSeed = 1; ///< unicycle initial headings (drawInitialHeading)
  double tolerance = 0.01;       ///< convergence: every pair distance within this of desired [m]
};

struct RobotLoopResult {
  long convergedStep = -1;     ///< first tick from which the error stays <= tolerance, or -1
  double convergedTime = -1.0; ///< convergedStep h [s], or -1
  double finalError = 0.0;     ///< max over pairs of |a_ij - d_ij| of the robots' points at the end [m]
  double maxErrorLastSecond = 0.0;
  long saturatedCommands = 0;  ///< unicycle commands scaled down by the limits
  double maxHeadingChange = 0.0; ///< largest |theta_end - theta_0| (wrapped) over the unicycles [rad]
};

/**
 * A ROS-free run of robot mode: one TimedAgent (robot mode, rate 1, every neighbour's newest state
 * from the previous tick) and one simulated robot (PointRobot or UnicycleRobot, whose hand point
 * is the agent's point) per agent, for the scenario's steps ticks of h. Odometry feedback: the
 * agent starts each tick from the odometry and the robot is sent the agent's velocity (the
 * robot-mode node as it is). Integrated feedback: the agent starts from correctedPosition and the
 * robot is sent v_k + k_p (q_k - odometry). The error is that of the robots' true points.
 * @throws InvalidInput on bad settings or a scenario with steps = 0.
 */
RobotLoopResult runRobotLoop(const Scenario& scenario, const RobotLoopSettings& settings);

}  // namespace vf
