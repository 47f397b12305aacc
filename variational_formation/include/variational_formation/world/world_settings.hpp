#pragma once

#include <string>
#include <vector>

namespace vf {

/// The robots of a MuJoCo world: the two kinds robot_sim simulates (doc/robots.md, "MuJoCo world").
enum class WorldKinematics {
  Holonomic,  ///< a base on planar x, y, yaw joints under velocity servos; cmd_vel linear on world axes
  Unicycle,   ///< a differential drive (TurtleBot3 Burger-like); cmd_vel linear.x and angular.z
};

/// "holonomic" or "unicycle" (robots.launch's kinematics). @throws InvalidInput "kinematics: ...".
WorldKinematics parseWorldKinematics(const std::string& text);
std::string kinematicsName(WorldKinematics kinematics);

/// A differential drive: a cylinder body on two wheels and a rear caster (TurtleBot3 Burger-like).
struct DifferentialDriveSettings {
  double wheelRadius = 0.033;     ///< [m] > 0
  double track = 0.16;            ///< distance between the wheels [m] > 0
  double maxWheelTorque = 0.1;    ///< motor torque limit per wheel [N m] > 0
  double maxWheelSpeed = 30.0;    ///< wheel speed commands are scaled into +-this [rad/s] > 0
  double wheelGain = 0.05;        ///< velocity servo gain kv [N m s/rad] > 0 (torque = kv (u - w))
  double wheelArmature = 2e-4;    ///< reflected motor inertia per wheel [kg m^2] >= 0 (keeps the servo stable)
  double casterFriction = 0.02;   ///< sliding friction coefficient of the caster on the floor, in [0, 10]
};

/// A holonomic base: a cylinder on planar joints, each under a velocity servo.
struct HolonomicBaseSettings {
  double maxForce = 10.0;         ///< servo force limit per axis [N] > 0
  double maxSpeed = 2.0;          ///< |cmd_vel linear| is scaled into this [m/s] > 0
  double baseGain = 20.0;         ///< velocity servo gain kv [N s/m] > 0 (force = kv (u - v))
};

/// Everything the world is built and stepped with; the ROS parameter of each field is named in
/// its check (validateWorldSettings), e.g. timeStep is ~time_step.
struct WorldSettings {
  WorldKinematics kinematics = WorldKinematics::Holonomic;
  double timeStep = 0.002;        ///< physics step [s] > 0
  double realTimeFactor = 1.0;    ///< simulated seconds per wall second; 0: as fast as possible (world as clock)
  double friction = 1.0;          ///< sliding friction of the wheels on the floor (and of the bodies), in (0, 10]
  double mass = 1.0;              ///< robot mass [kg] > 0
  double bodyRadius = 0.105;      ///< radius of the cylinder body [m] > 0
  double handOffset = 0.1;        ///< unicycle: the scenario's position is the hand point, this far ahead [m] > 0
  DifferentialDriveSettings drive;
  HolonomicBaseSettings base;
};

/**
 * Checks every field: time_step in (0, 0.05] s, real_time_factor >= 0, friction in (0, 10],
 * mass > 0 kg, body_radius > 0 m, hand_offset > 0 m, and the drive's (wheel_radius, track,
 * max_wheel_torque, max_wheel_speed, wheel_gain > 0; wheel_armature >= 0; caster_friction in
 * [0, 10]; the wheels within the body: track / 2 < body_radius) or the base's (max_force,
 * max_speed, base_gain > 0).
 * @throws InvalidInput naming the parameter, the value and the limit.
 */
void validateWorldSettings(const WorldSettings& settings);

/// The numbers of WorldSettings by their parameter names (time_step, friction, wheel_radius, ...),
/// as the node's private parameters and the step-response tool's flags spell them.
const std::vector<std::string>& worldParameterNames();
/// Sets the number named `name` (unchecked: validateWorldSettings checks the whole).
/// @throws InvalidInput for a name that is not one of worldParameterNames().
void setWorldParameter(WorldSettings& settings, const std::string& name, double value);

/// One line of the settings for a node's start-up log.
std::string describeWorldSettings(const WorldSettings& settings);

}  // namespace vf
