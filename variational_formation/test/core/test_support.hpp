#pragma once
// Small fixtures shared by the core tests.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <functional>
#include <initializer_list>
#include <string>
#include <vector>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/manoeuvres/command_schedule.hpp"
#include "variational_formation_core/manoeuvres/manoeuvre_integrator.hpp"
#include "variational_formation_core/model/scenario.hpp"

namespace vf {
namespace test {

inline std::string configPath(const std::string& name) {
  return std::string(VF_SOURCE_DIR) + "/config/" + name + ".yaml";
}

/// What `call` throws as InvalidInput, or "" if it does not throw.
template <class F>
std::string thrown(F call) {
  try {
    call();
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "";
}

/// `text` with the first `from` replaced by `to` (a failure if there is none).
inline std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

/// Expects parseScenario(yaml, "file.yaml") to throw InvalidInput: one line, prefixed by the
/// file, containing every fragment.
inline void expectError(const std::string& yaml, std::initializer_list<std::string> fragments) {
  try {
    parseScenario(yaml, "file.yaml");
    ADD_FAILURE() << "accepted:\n" << yaml;
  } catch (const InvalidInput& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_EQ(what.rfind("file.yaml: ", 0), 0u) << what;
    for (const auto& f : fragments) EXPECT_NE(what.find(f), std::string::npos) << what << " / " << f;
  }
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

/**
 * Expects `work` to end within `seconds`: it runs in a child process (a gtest death test) that
 * SIGALRM kills if it hangs, so a hang fails the test instead of hanging it. Check what it
 * computes afterwards, in the test itself, once this passed (`if (HasFailure()) return;`).
 */
inline void expectEndsWithin(unsigned seconds, const std::function<void()>& work) {
  EXPECT_EXIT(
      {
        alarm(seconds);
        work();
        std::_Exit(0);
      },
      ::testing::ExitedWithCode(0), "")
      << "did not end within " << seconds << " s (killed by SIGALRM: it hangs)";
}

}  // namespace test
}  // namespace vf
