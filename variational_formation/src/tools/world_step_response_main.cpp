// `world_step_response [--kinematics holonomic|unicycle] [--command V] [--<parameter> value...]`:
// the step response of one robot of the MuJoCo world with the mujoco_world node's parameters
// (doc/robots.md, "The MuJoCo world"). Prints "lag T rise_time T final V overshoot S"; make_agents_launch.py
// hands the lag to the agents' lag check. Exit 2 on bad input.
#include <iostream>
#include <map>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation/tools/arguments.hpp"
#include "variational_formation/tools/simulate_cli.hpp"
#include "variational_formation/world/step_response.hpp"

int main(int argc, char** argv) {
  try {
    std::map<std::string, int> flags{{"--kinematics", 1}, {"--command", 1}, {"--help", 0}, {"-h", 0}};
    for (const std::string& name : vf::worldParameterNames()) flags["--" + name] = 1;
    const vf::Arguments args(argc, argv, flags);
    if (args.has("--help") || args.has("-h")) {
      std::cout << "usage: world_step_response [--kinematics holonomic|unicycle] [--command V] [--<parameter> value...]\n"
                   "Steps cmd_vel linear.x of one robot of the MuJoCo world from 0 to V m/s (default 0.2) and\n"
                   "prints \"lag T rise_time T final V overshoot S\": T to 63.2% and from 10% to 90% [s], the\n"
                   "final speed [m/s], the overshoot as a share of V. Parameters: those of mujoco_world\n"
                   "(doc/ros_api.md), e.g. --time_step 0.002 --max_wheel_torque 0.1. Exit status 2 on bad input.\n";
      return vf::kExitOk;
    }
    vf::WorldSettings settings;
    settings.kinematics = vf::parseWorldKinematics(args.text("--kinematics", "holonomic"));
    for (const std::string& name : vf::worldParameterNames()) {
      if (args.has("--" + name)) vf::setWorldParameter(settings, name, args.number("--" + name));
    }
    const vf::StepResponse r =
        vf::measureStepResponse(settings, args.has("--command") ? args.number("--command") : 0.2);
    std::cout << "lag " << vf::formatNumber(r.lag) << " rise_time " << vf::formatNumber(r.riseTime) << " final "
              << vf::formatNumber(r.final) << " overshoot " << vf::formatNumber(r.overshoot) << '\n';
    return vf::kExitOk;
  } catch (const vf::InvalidInput& e) {
    std::cerr << "world_step_response: error: " << e.what() << '\n';
    return vf::kExitBadInput;
  }
}
