#include "variational_formation/tools/assign_slots_cli.hpp"

#include <cstdio>
#include <fstream>
#include <ostream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation/tools/arguments.hpp"
#include "variational_formation/tools/scenario_path.hpp"
#include "variational_formation/tools/simulate_cli.hpp"

namespace vf {

namespace {

const char* kUsage =
    "usage: assign_slots --scenario FILE|NAME --starts POSITIONS.csv [--out FILE]\n"
    "Makes the robots' current positions (POSITIONS.csv: agent,x,y,z, one row per agent, z = 0 in\n"
    "2D) the scenario's starts, chooses which agent takes which desired position (the permutation\n"
    "and rigid motion closest to the starts, as `assignment: auto` does at load; a mirror image only\n"
    "with `mirror: allowed`) and writes the scenario with the assignment applied (stdout without\n"
    "--out), ready to launch. Exit status 2 on bad input.\n";

std::string exact(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", x);
  return text;
}

YAML::Node point(const Positions& q, int i) {
  YAML::Node p(YAML::NodeType::Sequence);
  for (Eigen::Index a = 0; a < q.rows(); ++a) p.push_back(exact(q(a, i)));
  p.SetStyle(YAML::EmitterStyle::Flow);
  return p;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

int runAssignSlotsCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  try {
    const Arguments args(argc, argv, {{"--scenario", 1}, {"--starts", 1}, {"--out", 1}, {"--help", 0}, {"-h", 0}});
    if (args.has("--help") || args.has("-h")) {
      out << kUsage;
      return kExitOk;
    }
    args.require("--scenario");
    args.require("--starts");
    const std::string path = resolveScenario(args.text("--scenario"));
    const Scenario given = loadScenario(path);  // the one loader checks the file
    const Positions starts = loadStartPositions(args.text("--starts"), given);
    // The file's own fields, with the new starts, assigned by the loader itself.
    YAML::Node root = YAML::Load(readFile(path));
    for (int i = 0; i < given.agentCount(); ++i) root["agents"][i]["initial_position"] = point(starts, i);
    root["assignment"] = "auto";
    Scenario assigned = parseScenario(YAML::Dump(root), path + " with the starts of " + args.text("--starts"));
    root.remove("assignment");
    for (int i = 0; i < given.agentCount(); ++i) {
      root["agents"][i]["desired_position"] = point(assigned.desiredPositions, i);
      root["agents"][i].SetStyle(YAML::EmitterStyle::Flow);
    }
    YAML::Node edges(YAML::NodeType::Sequence);
    for (const auto& [i, j] : assigned.edges) {
      YAML::Node e(YAML::NodeType::Sequence);
      e.push_back(i);
      e.push_back(j);
      edges.push_back(e);
    }
    edges.SetStyle(YAML::EmitterStyle::Flow);
    root["edges"] = edges;
    for (const std::string& w : assigned.warnings) err << "assign_slots: warning: " << w << '\n';
    std::ostringstream yaml;
    yaml << "# assign_slots --scenario " << args.text("--scenario") << " --starts " << args.text("--starts") << "\n# "
         << assigned.assignment.describe() << "\n# Desired positions and edges follow the slots; starts from the robots.\n"
         << YAML::Dump(root) << '\n';
    parseScenario(yaml.str(), "the written scenario");  // what we write loads
    err << "assign_slots: " << assigned.assignment.describe() << '\n';
    return writeOutput(args, yaml.str(), "assign_slots", out, err);
  } catch (const InvalidInput& e) {
    err << "assign_slots: error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::exception& e) {
    err << "assign_slots: error: " << e.what() << '\n';
    return kExitFailure;
  }
}

}  // namespace vf
