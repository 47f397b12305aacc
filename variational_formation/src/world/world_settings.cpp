#include "variational_formation/world/world_settings.hpp"

#include <utility>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"

namespace vf {

WorldKinematics parseWorldKinematics(const std::string& text) {
  if (text == "holonomic") return WorldKinematics::Holonomic;
  if (text == "unicycle") return WorldKinematics::Unicycle;
  throw InvalidInput("kinematics: expected holonomic or unicycle, got '" + text + "'");
}

std::string kinematicsName(WorldKinematics kinematics) {
  return kinematics == WorldKinematics::Unicycle ? "unicycle" : "holonomic";
}

void validateWorldSettings(const WorldSettings& s) {
  // A step beyond 0.05 s leaves the contacts (time constant 0.02 s) and the servos unresolved.
  requireFiniteWithin("time_step", s.timeStep, 1e-6, 0.05, "s");
  requireFiniteAtLeast("real_time_factor", s.realTimeFactor, 0.0, "");
  requireFiniteWithin("friction", s.friction, 1e-6, 10.0, "");
  requireFiniteAbove("mass", s.mass, 0.0, "kg");
  requireFiniteAbove("body_radius", s.bodyRadius, 0.0, "m");
  requireFiniteAbove("hand_offset", s.handOffset, 0.0, "m");
  if (s.kinematics == WorldKinematics::Unicycle) {
    const DifferentialDriveSettings& d = s.drive;
    requireFiniteAbove("wheel_radius", d.wheelRadius, 0.0, "m");
    requireFiniteAbove("track", d.track, 0.0, "m");
    requireFiniteAbove("max_wheel_torque", d.maxWheelTorque, 0.0, "N m");
    requireFiniteAbove("max_wheel_speed", d.maxWheelSpeed, 0.0, "rad/s");
    requireFiniteAbove("wheel_gain", d.wheelGain, 0.0, "N m s/rad");
    requireFiniteAtLeast("wheel_armature", d.wheelArmature, 0.0, "kg m^2");
    requireFiniteWithin("caster_friction", d.casterFriction, 0.0, 10.0, "");
    // The wheels sit inside the body's outline, as on a TurtleBot3.
    if (!(0.5 * d.track < s.bodyRadius)) {
      throw InvalidInput("track: must be < 2 body_radius = " + formatNumber(2.0 * s.bodyRadius) + " m, got " +
                         formatNumber(d.track));
    }
  } else {
    requireFiniteAbove("max_force", s.base.maxForce, 0.0, "N");
    requireFiniteAbove("max_speed", s.base.maxSpeed, 0.0, "m/s");
    requireFiniteAbove("base_gain", s.base.baseGain, 0.0, "N s/m");
  }
}

namespace {

// Parameter name -> the field it sets.
const std::vector<std::pair<std::string, double WorldSettings::*>> kTop = {
    {"time_step", &WorldSettings::timeStep}, {"real_time_factor", &WorldSettings::realTimeFactor},
    {"friction", &WorldSettings::friction},   {"mass", &WorldSettings::mass},
    {"body_radius", &WorldSettings::bodyRadius}, {"hand_offset", &WorldSettings::handOffset}};
const std::vector<std::pair<std::string, double DifferentialDriveSettings::*>> kDrive = {
    {"wheel_radius", &DifferentialDriveSettings::wheelRadius},
    {"track", &DifferentialDriveSettings::track},
    {"max_wheel_torque", &DifferentialDriveSettings::maxWheelTorque},
    {"max_wheel_speed", &DifferentialDriveSettings::maxWheelSpeed},
    {"wheel_gain", &DifferentialDriveSettings::wheelGain},
    {"wheel_armature", &DifferentialDriveSettings::wheelArmature},
    {"caster_friction", &DifferentialDriveSettings::casterFriction}};
const std::vector<std::pair<std::string, double HolonomicBaseSettings::*>> kBase = {
    {"max_force", &HolonomicBaseSettings::maxForce}, {"max_speed", &HolonomicBaseSettings::maxSpeed},
    {"base_gain", &HolonomicBaseSettings::baseGain}};

}  // namespace

const std::vector<std::string>& worldParameterNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all;
    for (const auto& e : kTop) all.push_back(e.first);
    for (const auto& e : kDrive) all.push_back(e.first);
    for (const auto& e : kBase) all.push_back(e.first);
    return all;
  }();
  return names;
}

void setWorldParameter(WorldSettings& settings, const std::string& name, double value) {
  for (const auto& e : kTop) {
    if (e.first == name) return void(settings.*e.second = value);
  }
  for (const auto& e : kDrive) {
    if (e.first == name) return void(settings.drive.*e.second = value);
  }
  for (const auto& e : kBase) {
    if (e.first == name) return void(settings.base.*e.second = value);
  }
  throw InvalidInput(name + ": not a parameter of the MuJoCo world");
}

std::string describeWorldSettings(const WorldSettings& s) {
  std::string line = kinematicsName(s.kinematics) + ", time step " + formatNumber(s.timeStep) +
                     " s, real-time factor " + formatNumber(s.realTimeFactor) + ", friction " +
                     formatNumber(s.friction) + ", mass " + formatNumber(s.mass) + " kg, body radius " +
                     formatNumber(s.bodyRadius) + " m";
  if (s.kinematics == WorldKinematics::Unicycle) {
    const DifferentialDriveSettings& d = s.drive;
    line += ", wheels r " + formatNumber(d.wheelRadius) + " m on a track of " + formatNumber(d.track) +
            " m, up to " + formatNumber(d.maxWheelTorque) + " N m and " + formatNumber(d.maxWheelSpeed) +
            " rad/s, gain " + formatNumber(d.wheelGain) + " N m s/rad, armature " + formatNumber(d.wheelArmature) +
            " kg m^2, caster friction " + formatNumber(d.casterFriction);
  } else {
    line += ", servos up to " + formatNumber(s.base.maxForce) + " N and " + formatNumber(s.base.maxSpeed) +
            " m/s, gain " + formatNumber(s.base.baseGain) + " N s/m";
  }
  return line;
}

}  // namespace vf
