#include "variational_formation/tools/scenario_info_cli.hpp"

#include <ostream>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/rigidity.hpp"
#include "variational_formation_core/model/validation.hpp"
#include "variational_formation/tools/arguments.hpp"
#include "variational_formation/tools/scenario_path.hpp"
#include "variational_formation/tools/simulate_cli.hpp"

namespace vf {

namespace {

const char* kUsage =
    "usage: scenario_info --scenario FILE|NAME [--real-time-factor R] [--rigidity]\n"
    "Checks a scenario (and a pacing factor for it) through the package's one validation\n"
    "path and prints \"agents N\". On stderr: its warnings, and the graph's generic rigidity class\n"
    "(not rigid, rigid, minimally rigid, redundantly rigid or globally rigid), with a warning when it\n"
    "is not globally rigid; above 100 agents only with --rigidity (an O(E^3) test).\n"
    "Exit status 2 on bad input.\n";

}  // namespace

int runScenarioInfoCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  try {
    const Arguments args(argc, argv,
                         {{"--scenario", 1}, {"--real-time-factor", 1}, {"--rigidity", 0}, {"--help", 0}, {"-h", 0}});
    if (args.has("--help") || args.has("-h")) {
      out << kUsage;
      return kExitOk;
    }
    const Scenario s = loadScenario(resolveScenario(args.text("--scenario")));
    if (args.has("--real-time-factor")) {
      validateRealTimeFactor(args.number("--real-time-factor"), s.timeStep, "--real-time-factor");
    }
    for (const auto& w : s.warnings) err << "scenario_info: warning: " << w << '\n';
    if (s.agentCount() <= kMaxClassifiedAgents || args.has("--rigidity")) {
      const RigidityReport rigidity = classifyRigidity(makeFormation(s));
      err << "scenario_info: graph: " << rigidity.summary() << '\n';
      if (rigidity.rigidityClass != RigidityClass::GloballyRigid) {
        err << "scenario_info: warning: the graph is not globally rigid: the formation can settle in another "
               "shape with every edge at its length (make_scenario --graph complete builds one that is; "
               "doc/scenarios.md says when knn is better)\n";
      }
    }
    out << "agents " << s.agentCount() << '\n';
    return kExitOk;
  } catch (const InvalidInput& e) {
    err << "scenario_info: error: " << e.what() << '\n';
    return kExitBadInput;
  }
}

}  // namespace vf
