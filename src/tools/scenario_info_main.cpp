// `scenario_info --scenario FILE|NAME [--real-time-factor R]`: validates a scenario (and a pacing
// factor) through the one validation path and prints "agents N" (and its warnings on stderr).
// Used by the launch files; exit 2 on bad input.
#include <iostream>

#include "variational_formation/core/error.hpp"
#include "variational_formation/core/validation.hpp"
#include "variational_formation/tools/arguments.hpp"
#include "variational_formation/tools/simulate_cli.hpp"
#include "variational_formation/tools/scenario_path.hpp"

int main(int argc, char** argv) {
  try {
    const vf::Arguments args(argc, argv, {{"--scenario", 1}, {"--real-time-factor", 1}, {"--help", 0}, {"-h", 0}});
    if (args.has("--help") || args.has("-h")) {
      std::cout << "usage: scenario_info --scenario FILE|NAME [--real-time-factor R]\n"
                   "Checks a scenario (and a pacing factor for it) through the package's one validation\n"
                   "path and prints \"agents N\"; warnings go to stderr. Exit status 2 on bad input.\n";
      return vf::kExitOk;
    }
    const vf::Scenario s = vf::loadScenario(vf::resolveScenario(args.text("--scenario")));
    if (args.has("--real-time-factor")) {
      vf::validateRealTimeFactor(args.number("--real-time-factor"), s.timeStep, "--real-time-factor");
    }
    for (const auto& w : s.warnings) std::cerr << "scenario_info: warning: " << w << '\n';
    std::cout << "agents " << s.agentCount() << '\n';
    return vf::kExitOk;
  } catch (const vf::InvalidInput& e) {
    std::cerr << "scenario_info: error: " << e.what() << '\n';
    return vf::kExitBadInput;
  }
}
