#pragma once

#include <deque>
#include <string>
#include <utility>
#include <vector>

#include "variational_formation_core/model/formation.hpp"
#include "variational_formation_core/robots/robot_mode.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/model/shape_outcome.hpp"

namespace vf {

/// How the monitor measures the robots of a robot-mode run (doc/robots.md, "Converged means the robots").
struct RobotShapeSettings {
  RobotKinematics kinematics = RobotKinematics::Holonomic;
  double handOffset = 0.1;  ///< unicycle: the hand point's distance ahead of the axle [m] > 0
  double window = 0.5;      ///< each robot's point is its odometry averaged over this long [s] > 0
  double silentAfter = 1.0; ///< a robot without odometry for this long is not measured [s] > 0
  double tolerance = 0.01;  ///< relative, as the agents' congruence (every pair within tol s d_ij)
};

/// The robots at one monitor step.
struct RobotShapeStep {
  bool measured = false;  ///< every robot has odometry, none silent: the findings are the robots'
  ShapeFindings findings; ///< of the averaged points, velocities taken as zero (NaN errors if not measured)
  long inShapeSince = -1; ///< first step of the robots' current in-shape stretch, -1 if not in shape
  std::string unmeasured; ///< why not measured: "no odometry from robot_3", "robot_2 silent for 1.4 s"
};

/**
 * The robots of a robot-mode run as the monitor sees them, without ROS: each robot's odometry
 * (pointFromOdometry: the position, or a unicycle's hand point) averaged over the newest `window`
 * seconds, so that the odometry noise (1 cm in robots.launch) does not decide the verdict; at each
 * monitor step the robots' max distance error and shape error (Formation's, as for the agents)
 * and whether they are in the desired shape: every pair within the agents' relative tolerance
 * (CongruenceTracker, velocities zero: the speeds are the agents' part of the verdict, and a
 * velocity from noisy odometry would be mostly noise), kept from step to step as the agents'
 * congruent stretch is.
 */
class RobotShapeWatch {
 public:
  /// @throws InvalidInput naming the setting (hand_offset, robots_window, kinematics) on a bad one.
  RobotShapeWatch(const Scenario& scenario, const RobotShapeSettings& settings);

  /**
   * Robot `id`'s odometry pose (position [m], quaternion), received at time t [s] (any clock
   * that the calls to observe share). @throws InvalidInput "robot_<id>: odometry: ..." on a bad
   * id or a bad pose (nothing is kept then).
   */
  void addOdometry(int id, double t, double x, double y, double z, double qx, double qy, double qz, double qw);

  /// Robots without any odometry yet.
  std::vector<int> unheard() const;
  /// Robots heard once but silent for more than silentAfter at time `now` [s].
  std::vector<int> silent(double now) const;

  /**
   * The robots at monitor step `step` (in order), time `now` [s], against s d_ij (s = `scale`,
   * the commanded scale the step is measured under). The O(n^2) shape error follows
   * shapeErrorMeasuredAt, as the agents'.
   */
  const RobotShapeStep& observe(long step, double now, double scale);
  const RobotShapeStep& last() const { return last_; }
  /// Each robot's averaged point at the last observe (d x n) [m].
  const Positions& points() const { return points_; }

  /**
   * The robots' own verdict at the last observed step, as shapeOutcome gives the agents'
   * (desired shape; with every edge right, the mirror image or folded, since the robots'
   * velocities are not measured; or not converged; a run in which some robot was never measured
   * is not converged). @param timeStep h [s].
   */
  ShapeOutcome outcome(double timeStep) const;

 private:
  Formation formation_;
  RobotShapeSettings settings_;
  int dimension_;
  long lastStep_;
  bool mirrorAllowed_;
  std::vector<std::deque<std::pair<double, std::vector<double>>>> odometry_;  // per robot: (t, point), newest last
  CongruenceTracker congruence_;
  Positions points_;
  double scale_ = 1.0;
  RobotShapeStep last_;
};

/**
 * The verdict of a robot-mode run (doc/robots.md, "Converged means the robots"): the worse of the
 * agents' and the robots' verdicts (not converged < a shape with every edge right < the desired
 * shape). Both in the desired shape: converged at the later of the two steps. The robots folded
 * while the agents are in the desired shape: still settling (the robots follow the agents and have
 * not caught up). The robots worse: their verdict, in
 * a line that says it is the robots' ("not converged (the robots, from odometry: max distance
 * error E m, shape error S m)"), with their findings, so that the run's reason gives their error.
 * @param timeStep h [s].
 */
ShapeOutcome robotModeOutcome(const ShapeOutcome& agents, const ShapeOutcome& robots, double timeStep);

}  // namespace vf
