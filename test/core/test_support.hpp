#pragma once
// Small fixtures shared by the core tests.

#include <string>

#include <vector>

#include "variational_formation/core/manoeuvre_command.hpp"
#include "variational_formation/core/manoeuvre_integrator.hpp"
#include "variational_formation/core/scenario.hpp"

namespace vf {
namespace test {

inline std::string configPath(const std::string& name) {
  return std::string(VF_SOURCE_DIR) + "/config/" + name + ".yaml";
}

/// A 2D triangle (side 1) with its three edges.
inline Formation triangle() {
  Positions shape(2, 3);
  shape << 0.0, 1.0, 0.5, 0.0, 0.0, 0.8660254037844386;
  return Formation(2, shape, {{0, 1}, {1, 2}, {2, 0}});
}

/// Regular tetrahedron of side 2 with K4.
inline Formation tetrahedron() {
  const double a = 0.7071067811865475;
  Positions shape(3, 4);
  shape << a, a, -a, -a, a, -a, a, -a, a, -a, -a, a;
  return Formation(3, shape, {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}});
}

/// A command v* [m/s], omega* [rad/s], s.
inline Command command(const Vector3& velocity, const Vector3& angularRate, double scale) {
  Command c;
  c.velocity = velocity;
  c.angularRate = angularRate;
  c.scale = scale;
  return c;
}

/// q_0 .. q_steps of the centralised run of `s` under `schedule` (ManoeuvreIntegrator).
inline std::vector<Positions> manoeuvreTrajectory(const Scenario& s, const CommandSchedule& schedule) {
  const Formation f = makeFormation(s);  // the integrator keeps a reference to it
  ManoeuvreIntegrator reference(f, s.initialPositions, s.initialVelocities, s.timeStep, s.dampingGain,
                                StartMethod::Variational, schedule);
  std::vector<Positions> trajectory{reference.positions()};
  for (long k = 0; k < s.steps; ++k) {
    reference.step();
    trajectory.push_back(reference.positions());
  }
  return trajectory;
}

}  // namespace test
}  // namespace vf
