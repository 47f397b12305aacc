#include "variational_formation/world/mjcf_model.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/model/validation.hpp"

namespace vf {

namespace {

// Heights [m]: the body's cylinder clears the floor by kClearance, so only wheels and caster
// (differential drive) or nothing (holonomic base, carried by its planar joints) touch it.
constexpr double kClearance = 0.01;
constexpr double kBodyHalfHeight = 0.04;
constexpr double kWheelHalfWidth = 0.009;
constexpr double kCasterRadius = 0.01;
// Each wheel weighs this share of the robot; the body's centre sits this far behind the axle
// [share of the body radius], loading the rear caster as on a TurtleBot3 Burger.
constexpr double kWheelMassShare = 0.05;
constexpr double kBodyOffsetShare = 0.4;
// Bodies meet with a stiffer contact than MuJoCo's default (time constant 0.02 s): robots
// pressed together by their motors overlap by millimetres, not a centimetre.
const char* const kBodyContact = " solref=\"0.005 1\" solimp=\"0.95 0.99 0.001\"";

std::string n(double value) { return formatNumber(value); }

void differentialDrive(std::ostringstream& out, const WorldSettings& s, int i, const PlanarPose& p) {
  const DifferentialDriveSettings& d = s.drive;
  const std::string name = "robot_" + std::to_string(i);
  const double wheelMass = kWheelMassShare * s.mass;
  const double bodyZ = kClearance - d.wheelRadius + kBodyHalfHeight;  // relative to the axle
  const double f = s.friction;
  // The base's origin is the axle's midpoint, at wheel height: pose() is robot_sim's axle pose.
  out << "    <body name=\"" << name << "\" pos=\"" << n(p.x) << ' ' << n(p.y) << ' ' << n(d.wheelRadius)
      << "\" euler=\"0 0 " << n(p.heading) << "\">\n"
      << "      <freejoint name=\"" << name << "_base\"/>\n"
      << "      <geom name=\"" << name << "_body\" type=\"cylinder\" size=\"" << n(s.bodyRadius) << ' '
      << n(kBodyHalfHeight) << "\" pos=\"" << n(-kBodyOffsetShare * s.bodyRadius) << " 0 " << n(bodyZ)
      << "\" mass=\"" << n(s.mass - 2.0 * wheelMass) << "\" friction=\"" << n(f) << " 0.005 0.0001\"" << kBodyContact << "/>\n"
      << "      <geom name=\"" << name << "_caster\" type=\"sphere\" size=\"" << n(kCasterRadius) << "\" pos=\""
      << n(-0.75 * s.bodyRadius) << " 0 " << n(kCasterRadius - d.wheelRadius) << "\" mass=\"0\" friction=\""
      << n(d.casterFriction) << " 0.005 0.0001\"/>\n";
  for (const char* side : {"left", "right"}) {
    const double y = (side[0] == 'l' ? 0.5 : -0.5) * d.track;
    out << "      <body name=\"" << name << '_' << side << "_wheel\" pos=\"0 " << n(y) << " 0\">\n"
        << "        <joint name=\"" << name << '_' << side << "_wheel\" type=\"hinge\" axis=\"0 1 0\" armature=\""
        << n(d.wheelArmature) << "\"/>\n"
        << "        <geom type=\"cylinder\" size=\"" << n(d.wheelRadius) << ' ' << n(kWheelHalfWidth)
        << "\" zaxis=\"0 1 0\" mass=\"" << n(wheelMass) << "\" friction=\"" << n(f) << " 0.005 0.0001\"/>\n"
        << "      </body>\n";
  }
  out << "    </body>\n";
}

void holonomicBase(std::ostringstream& out, const WorldSettings& s, int i, const PlanarPose& p) {
  const std::string name = "robot_" + std::to_string(i);
  const double c = std::cos(p.heading), sn = std::sin(p.heading);
  out << "    <body name=\"" << name << "\" pos=\"" << n(p.x) << ' ' << n(p.y) << ' '
      << n(kClearance + kBodyHalfHeight) << "\" euler=\"0 0 " << n(p.heading) << "\">\n"
      // The slides move along the world's x and y whatever the start heading: their axes are
      // given in the body's frame, the world's axes turned back by the heading.
      << "      <joint name=\"" << name << "_x\" type=\"slide\" axis=\"" << n(c) << ' ' << n(-sn) << " 0\"/>\n"
      << "      <joint name=\"" << name << "_y\" type=\"slide\" axis=\"" << n(sn) << ' ' << n(c) << " 0\"/>\n"
      << "      <joint name=\"" << name << "_yaw\" type=\"hinge\" axis=\"0 0 1\"/>\n"
      << "      <geom name=\"" << name << "_body\" type=\"cylinder\" size=\"" << n(s.bodyRadius) << ' '
      << n(kBodyHalfHeight) << "\" mass=\"" << n(s.mass) << "\" friction=\"" << n(s.friction)
      << " 0.005 0.0001\"" << kBodyContact << "/>\n"
      << "    </body>\n";
}

void actuators(std::ostringstream& out, const WorldSettings& s, int i) {
  const std::string name = "robot_" + std::to_string(i);
  auto servo = [&out](const std::string& actuator, const std::string& joint, double gain, double limit) {
    out << "    <velocity name=\"" << actuator << "\" joint=\"" << joint << "\" kv=\"" << n(gain)
        << "\" forcelimited=\"true\" forcerange=\"" << n(-limit) << ' ' << n(limit) << "\"/>\n";
  };
  if (s.kinematics == WorldKinematics::Unicycle) {
    for (const char* side : {"left", "right"}) {
      const std::string wheel = name + '_' + side + "_wheel";
      servo(wheel, wheel, s.drive.wheelGain, s.drive.maxWheelTorque);
    }
    return;
  }
  servo(name + "_x", name + "_x", s.base.baseGain, s.base.maxForce);
  servo(name + "_y", name + "_y", s.base.baseGain, s.base.maxForce);
  // Yaw with the same time constant as x and y: gain and limit scaled by I_zz / m = r^2 / 2.
  const double inertiaPerMass = 0.5 * s.bodyRadius * s.bodyRadius;
  servo(name + "_yaw", name + "_yaw", s.base.baseGain * inertiaPerMass, s.base.maxForce * s.bodyRadius);
}

}  // namespace

std::vector<PlanarPose> worldStartPoses(const Scenario& scenario, const WorldSettings& settings,
                                        std::uint64_t headingSeed) {
  if (scenario.dimension != 2) {
    throw InvalidInput("dimension: the MuJoCo world is planar (robots on a floor), got " +
                       std::to_string(scenario.dimension));
  }
  std::vector<PlanarPose> starts;
  for (int i = 0; i < scenario.agentCount(); ++i) {
    const double p[2] = {scenario.initialPositions(0, i), scenario.initialPositions(1, i)};
    if (settings.kinematics == WorldKinematics::Holonomic) {
      starts.push_back({p[0], p[1], 0.0});
      continue;
    }
    // As robot_sim: the scenario's headings if it has any (0 where an agent gives none), else drawn.
    const double heading = scenario.initialHeadings.empty() ? drawInitialHeading(headingSeed, i)
                                                            : initialHeading(scenario, i);
    starts.push_back(axleFromHandPoint(p, heading, settings.handOffset));
  }
  return starts;
}

std::vector<StaticObstacle> worldObstacles(const Scenario& scenario, double height) {
  if (scenario.dimension != 2 && !scenario.obstacles.empty()) {
    throw InvalidInput("dimension: the MuJoCo world is planar (obstacles on a floor), got " +
                       std::to_string(scenario.dimension));
  }
  std::vector<StaticObstacle> out;
  for (const Obstacle& o : scenario.obstacles) {
    StaticObstacle s;
    s.height = height;
    if (o.shape == Obstacle::Shape::Ball) {
      s.x = o.centre.x();
      s.y = o.centre.y();
      s.radius = std::max(o.radius, kMinObstacleHalfWidth);
    } else {
      s.shape = StaticObstacle::Shape::Box;
      s.x = 0.5 * (o.min.x() + o.max.x());
      s.y = 0.5 * (o.min.y() + o.max.y());
      s.halfX = std::max(0.5 * (o.max.x() - o.min.x()), kMinObstacleHalfWidth);
      s.halfY = std::max(0.5 * (o.max.y() - o.min.y()), kMinObstacleHalfWidth);
    }
    out.push_back(s);
  }
  return out;
}

std::string buildWorldMjcf(const WorldSettings& settings, const std::vector<PlanarPose>& starts,
                           const std::vector<StaticObstacle>& obstacles) {
  validateWorldSettings(settings);
  if (starts.empty()) throw InvalidInput("robots: a world needs at least one robot");
  for (std::size_t i = 0; i < starts.size(); ++i) {
    const PlanarPose& p = starts[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.heading)) {
      throw InvalidInput("robot_" + std::to_string(i) + ": start pose must be finite, got (" + n(p.x) + ", " +
                         n(p.y) + ", " + n(p.heading) + ")");
    }
  }
  for (std::size_t k = 0; k < obstacles.size(); ++k) {
    const StaticObstacle& o = obstacles[k];
    const std::string field = "obstacles[" + std::to_string(k) + "]";
    if (!std::isfinite(o.x) || !std::isfinite(o.y)) {
      throw InvalidInput(field + ": centre must be finite, got (" + n(o.x) + ", " + n(o.y) + ")");
    }
    if (o.shape == StaticObstacle::Shape::Box) {
      requireFiniteAbove(field + ".half_x", o.halfX, 0.0, "m");
      requireFiniteAbove(field + ".half_y", o.halfY, 0.0, "m");
    } else {
      requireFiniteAbove(field + ".radius", o.radius, 0.0, "m");
    }
    requireFiniteAbove(field + ".height", o.height, 0.0, "m");
  }
  const int count = static_cast<int>(starts.size());
  // Contact buffers sized for every robot's floor contacts plus robots touching each other.
  const int contacts = 16 * count + 8 * static_cast<int>(obstacles.size()) + 64;
  std::ostringstream out;
  out << "<mujoco model=\"variational_formation_world\">\n"
      << "  <compiler angle=\"radian\"/>\n"
      // Semi-implicit Euler, with the wheels' armature keeping the servos stable (the implicit
      // integrator of 2.2.2 is dense in the degrees of freedom: 30 times slower at 50 robots).
      // Elliptic friction cones and a sparse Jacobian: the solver converges in a step or two and
      // its cost grows with the robots, not their square (doc/robots.md, "The MuJoCo world").
      << "  <option timestep=\"" << n(settings.timeStep)
      << "\" integrator=\"Euler\" cone=\"elliptic\" jacobian=\"sparse\" solver=\"CG\"/>\n"
      << "  <size nconmax=\"" << contacts << "\" njmax=\"" << 6 * contacts << "\"/>\n"
      << "  <worldbody>\n"
      // The floor's own friction is the lowest: MuJoCo takes the larger of two geoms' values, so
      // the wheels grip with `friction` and the caster slides with `caster_friction`.
      << "    <geom name=\"floor\" type=\"plane\" size=\"0 0 1\" friction=\"1e-6 0.005 0.0001\"/>\n";
  for (std::size_t k = 0; k < obstacles.size(); ++k) {
    const StaticObstacle& o = obstacles[k];
    const bool box = o.shape == StaticObstacle::Shape::Box;
    out << "    <geom name=\"obstacle_" << k << "\" type=\"" << (box ? "box" : "cylinder") << "\" size=\"";
    if (box) out << n(o.halfX) << ' ' << n(o.halfY) << ' ';
    else out << n(o.radius) << ' ';
    // As stiff as the robots' bodies: a robot pushed against it by its motors stops within millimetres.
    out << n(0.5 * o.height) << "\" pos=\"" << n(o.x) << ' ' << n(o.y) << ' ' << n(0.5 * o.height)
        << "\" friction=\"" << n(settings.friction) << " 0.005 0.0001\"" << kBodyContact << "/>\n";
  }
  for (int i = 0; i < count; ++i) {
    if (settings.kinematics == WorldKinematics::Unicycle) differentialDrive(out, settings, i, starts[i]);
    else holonomicBase(out, settings, i, starts[i]);
  }
  out << "  </worldbody>\n  <actuator>\n";
  for (int i = 0; i < count; ++i) actuators(out, settings, i);
  out << "  </actuator>\n</mujoco>\n";
  return out.str();
}

}  // namespace vf
