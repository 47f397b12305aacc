#include "variational_formation/world/step_response.hpp"

#include <algorithm>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation/world/mjcf_model.hpp"
#include "variational_formation/world/mujoco_world.hpp"

namespace vf {

namespace {

// The time the speed first reaches `level`, interpolated between steps; -1 if never.
double crossing(const std::vector<double>& times, const std::vector<double>& speeds, double level) {
  for (std::size_t k = 1; k < speeds.size(); ++k) {
    if (speeds[k] >= level && speeds[k - 1] < level) {
      return times[k - 1] + (level - speeds[k - 1]) / (speeds[k] - speeds[k - 1]) * (times[k] - times[k - 1]);
    }
  }
  return -1.0;
}

}  // namespace

StepResponse measureStepResponse(const WorldSettings& settings, double command, double duration) {
  requireFiniteAbove("command", command, 0.0, "m/s");
  requireFiniteAbove("duration", duration, 0.0, "s");
  MujocoWorld world(buildWorldMjcf(settings, {PlanarPose{}}), "step response", 1, settings);
  while (world.time() < 0.2) world.step();  // the wheels settle into the floor
  const double start = world.time();
  world.setCommand(0, command, 0.0, 0.0);
  std::vector<double> times{0.0}, speeds{world.twist(0).linearX};
  while (world.time() - start < duration) {
    world.step();
    times.push_back(world.time() - start);
    speeds.push_back(world.twist(0).linearX);
  }
  StepResponse r;
  r.command = command;
  r.lag = crossing(times, speeds, 0.632 * command);
  if (r.lag < 0) {
    throw InvalidInput("command: the robot never reached 63.2% of " + formatNumber(command) + " m/s in " +
                       formatNumber(duration) + " s");
  }
  r.riseTime = crossing(times, speeds, 0.9 * command) - crossing(times, speeds, 0.1 * command);
  r.final = speeds.back();
  r.overshoot = std::max(0.0, (*std::max_element(speeds.begin(), speeds.end()) - command) / command);
  return r;
}

}  // namespace vf
