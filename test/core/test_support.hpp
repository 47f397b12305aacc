#pragma once
// Small fixtures shared by the core tests.

#include <string>

#include "variational_formation/core/manoeuvre_command.hpp"
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

}  // namespace test
}  // namespace vf
