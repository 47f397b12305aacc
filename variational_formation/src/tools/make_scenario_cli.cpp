#include "variational_formation/tools/make_scenario_cli.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <ostream>
#include <set>
#include <sstream>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/integrators/step_size_advice.hpp"
#include "variational_formation/tools/arguments.hpp"
#include "variational_formation/tools/deployment.hpp"
#include "variational_formation_core/generators/formation_generators.hpp"
#include "variational_formation_core/generators/globally_rigid_graph.hpp"
#include "variational_formation/tools/simulate_cli.hpp"

namespace vf {

namespace {

const char* kUsage =
    "usage: make_scenario --shape grid --rows R --cols C\n"
    "       make_scenario --shape ring --agents N [--chords K]       (K = 1: chords to the 2nd neighbour)\n"
    "       make_scenario --shape lattice --rows R --cols C --layers L  (3D, braced)\n"
    "       make_scenario --shape henneberg --agents N --dimension 2|3 [--seed S]\n"
    "   common: [--spacing S] [--perturb SIGMA] [--seed S] [--kappa K] [--time-step H]\n"
    "           [--steps N] [--name NAME] [--out FILE] [--graph complete|knn[:K]]\n"
    "           [--scatter SIDE [--min-gap G]] [--safety r R GAMMA [--max-speed V]]\n"
    "Writes a rigid formation scenario (YAML, stdout without --out). Desired neighbours are\n"
    "--spacing apart (default 1 m). The start is the desired position plus, per coordinate,\n"
    "uniform noise on [-SIGMA, SIGMA] (default 0.1 * spacing) drawn from --seed (default 1).\n"
    "--scatter: starts uniform in a square (cube) of side SIDE round the desired centroid, at\n"
    "least G apart (default r of --safety, else 0); --safety adds a safety: block (doc/scenarios.md).\n"
    "Defaults: kappa 2, h 0.005 s (refused if not below the linear stability limit), 4000 steps.\n"
    "A graph that is not infinitesimally rigid is refused. --graph replaces the shape's edges by a\n"
    "globally rigid graph: every pair, or each agent's K nearest (K >= d + 1, default d + 1), K grown\n"
    "until globally rigid. Exit status 2 on bad input.\n";

constexpr int kMaxAgents = 2000;  // the rank test is an SVD, O(n^3)
constexpr double kDefaultDampingGain = 2.0;
constexpr double kDefaultTimeStep = 0.005;
constexpr long kDefaultSteps = 4000;

/// Shape -> the shape-specific flags it takes (the common ones are always allowed).
const std::map<std::string, std::set<std::string>> kShapeFlags = {
    {"grid", {"--rows", "--cols"}},
    {"ring", {"--agents", "--chords"}},
    {"lattice", {"--rows", "--cols", "--layers"}},
    {"henneberg", {"--agents", "--dimension"}},
};
const std::set<std::string> kShapeSpecificFlags = {"--rows",   "--cols",   "--layers",
                                                   "--agents", "--chords", "--dimension"};

std::string number(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

int count(const Arguments& args, const std::string& flag) {
  return static_cast<int>(args.integer(flag, 1, kMaxAgents));
}

void requireAtMostMaxAgents(const std::string& flags, long agents) {
  if (agents > kMaxAgents) {
    throw InvalidInput(flags + ": " + std::to_string(agents) + " agents, more than " +
                       std::to_string(kMaxAgents));
  }
}

struct Generated {
  FormationGraph graph;
  std::string name;
  std::string description;
};

Generated generate(const Arguments& args, const std::string& shape, double spacing,
                   std::uint64_t seed) {
  Generated g;
  if (shape == "grid") {
    const int rows = count(args, "--rows"), cols = count(args, "--cols");
    requireAtMostMaxAgents("--rows x --cols", static_cast<long>(rows) * cols);
    g.graph = triangulatedGrid(rows, cols, spacing);
    g.name = "grid_" + std::to_string(rows) + "x" + std::to_string(cols);
    g.description = "triangulated grid, " + std::to_string(rows) + " rows x " +
                    std::to_string(cols) + " columns";
  } else if (shape == "ring") {
    const int n = count(args, "--agents");
    const int chords = args.has("--chords") ? static_cast<int>(args.integer("--chords", 0, kMaxAgents)) : 1;
    g.graph = ringWithChords(n, chords, spacing);
    g.name = "ring_" + std::to_string(n);
    g.description = "ring of " + std::to_string(n) + " with chords to the next " +
                    std::to_string(chords) + " neighbour(s) after the first";
  } else if (shape == "lattice") {
    const int rows = count(args, "--rows"), cols = count(args, "--cols");
    const int layers = count(args, "--layers");
    requireAtMostMaxAgents("--rows x --cols x --layers", static_cast<long>(rows) * cols * layers);
    g.graph = bracedLattice(rows, cols, layers, spacing);
    g.name = "lattice_" + std::to_string(rows) + "x" + std::to_string(cols) + "x" +
             std::to_string(layers);
    g.description = "3D lattice, " + std::to_string(rows) + " rows x " + std::to_string(cols) +
                    " columns x " + std::to_string(layers) + " layers, one diagonal per face";
  } else {
    const int n = count(args, "--agents");
    const int dimension = static_cast<int>(args.integer("--dimension", 2, 3));
    g.graph = hennebergConstruction(n, dimension, seed, spacing);
    g.name = "henneberg_" + std::to_string(n) + "_" + std::to_string(dimension) + "d";
    g.description = "random Henneberg type-I construction in " + std::to_string(dimension) +
                    "D, seed " + std::to_string(seed);
  }
  return g;
}

/// Throws unless the shape's flags are all given and no other shape's flag is.
void checkShapeFlags(const Arguments& args, const std::string& shape) {
  const auto it = kShapeFlags.find(shape);
  if (it == kShapeFlags.end()) {
    throw InvalidInput("--shape: unknown shape '" + shape + "' (known: grid, ring, lattice, henneberg)");
  }
  for (const std::string& flag : kShapeSpecificFlags) {
    if (args.has(flag) && !it->second.count(flag)) {
      throw InvalidInput(flag + ": not used by --shape " + shape);
    }
  }
  for (const std::string& flag : it->second) {
    if (flag != "--chords") args.require(flag);
  }
}

/// h from --time-step (a warning if the stability advice rejects it), or the default if the
/// advice accepts it.
double chooseTimeStep(const Arguments& args, const Formation& formation, const Scenario& s,
                      std::ostream& err) {
  const bool given = args.has("--time-step");
  const double h = given ? args.positiveNumber("--time-step") : kDefaultTimeStep;
  const StepSizeAdvice advice = adviseTimeStep(formation, s.initialPositions, h, s.dampingGain);
  if (given) {
    if (advice.exceeded) err << "make_scenario: warning: " << advice.message << '\n';
    return h;
  }
  if (advice.exceeded) {
    throw InvalidInput("--time-step: the default " + number(kDefaultTimeStep) +
                       " s is not below this formation's linear stability limit " +
                       number(advice.limit) + " s; give a smaller --time-step");
  }
  return kDefaultTimeStep;
}

std::string commandLine(int argc, const char* const* argv) {
  std::string line = "make_scenario";
  for (int a = 1; a < argc; ++a) line += std::string(" ") + argv[a];
  return line;
}

}  // namespace

void writeScenarioYaml(const Scenario& s, const std::vector<std::string>& comments,
                       std::ostream& out) {
  const auto vector = [&out](const Eigen::VectorXd& v) {
    out << '[';
    for (Eigen::Index a = 0; a < v.size(); ++a) out << (a ? ", " : "") << v(a);
    out << ']';
  };
  const auto oldPrecision = out.precision(17);
  for (const std::string& c : comments) out << "# " << c << '\n';
  out << "name: " << s.name << "\ndimension: " << s.dimension << "\nkappa: " << s.dampingGain
      << "\ntime_step: " << s.timeStep << "\nsteps: " << s.steps << "\nagents:\n";
  for (int i = 0; i < s.agentCount(); ++i) {
    out << "  - {id: " << i << ", initial_position: ";
    vector(s.initialPositions.col(i));
    out << ", initial_velocity: ";
    vector(s.initialVelocities.col(i));
    out << ", desired_position: ";
    vector(s.desiredPositions.col(i));
    out << "}\n";
  }
  out << "edges: [";
  for (std::size_t e = 0; e < s.edges.size(); ++e) {
    out << (e == 0 ? "" : ",") << (e % 8 == 0 ? "\n  " : " ") << '[' << s.edges[e].first << ", "
        << s.edges[e].second << ']';
  }
  out << "]\n";
  writeSafetyYaml(s, out);
  out.precision(oldPrecision);
}

int runMakeScenarioCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  try {
    const Arguments args(argc, argv,
                         {{"--shape", 1}, {"--rows", 1}, {"--cols", 1}, {"--layers", 1},
                          {"--agents", 1}, {"--chords", 1}, {"--dimension", 1}, {"--spacing", 1},
                          {"--perturb", 1}, {"--seed", 1}, {"--kappa", 1}, {"--time-step", 1},
                          {"--steps", 1}, {"--name", 1}, {"--out", 1}, {"--graph", 1},
                          {"--scatter", 1}, {"--min-gap", 1}, {"--safety", 3}, {"--max-speed", 1}, {"--help", 0}, {"-h", 0}});
    if (args.has("--help") || args.has("-h")) {
      out << kUsage;
      return kExitOk;
    }
    const std::string shape = args.text("--shape");
    checkShapeFlags(args, shape);
    const double spacing = args.has("--spacing") ? args.positiveNumber("--spacing") : 1.0;
    const double sigma = args.has("--perturb") ? args.number("--perturb") : 0.1 * spacing;
    if (sigma < 0.0) throw InvalidInput("--perturb: must be >= 0, got '" + args.text("--perturb") + "'");
    const auto seed = static_cast<std::uint64_t>(
        args.has("--seed") ? args.integer("--seed", 0, std::numeric_limits<long>::max()) : 1);

    const Generated g = generate(args, shape, spacing, seed);
    Scenario s;
    s.name = args.text("--name", g.name);
    // A YAML plain scalar that loads back as this string (not null, no flow punctuation).
    std::string lower = s.name;
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
    if (s.name.empty() || s.name.find_first_of(":#{}[],&*!|>'\"%@`\n") != std::string::npos ||
        s.name.front() == ' ' || s.name.front() == '-' || s.name.back() == ' ' || lower == "null" ||
        s.name == "~") {
      throw InvalidInput("--name: must be a plain non-empty word (none of :#{}[],&*!|>'\"%@` or null), got '" +
                         s.name + "'");
    }
    s.dimension = g.graph.dimension;
    s.dampingGain = kDefaultDampingGain;
    if (args.has("--kappa")) {
      s.dampingGain = args.number("--kappa");
      if (s.dampingGain < 0.0) throw InvalidInput("--kappa: must be >= 0, got '" + args.text("--kappa") + "'");
    }
    s.steps = args.has("--steps") ? args.integer("--steps", 1, std::numeric_limits<long>::max() / 2)
                                  : kDefaultSteps;
    s.desiredPositions = g.graph.desiredPositions;
    s.initialPositions = perturbedPositions(s.desiredPositions, sigma, seed);
    s.initialVelocities.setZero(s.dimension, s.desiredPositions.cols());
    s.edges = g.graph.edges;
    std::string graphComment;  // the graph's class; --graph: a globally rigid graph replaces the shape's edges
    if (args.has("--graph")) {
      const GloballyRigidGraph rigid = globallyRigidGraph(args.text("--graph"), s.desiredPositions);
      s.edges = rigid.edges;
      graphComment = "graph: " + rigid.description + ": " + rigid.rigidity.summary();
    } else if (s.agentCount() <= kMaxClassifiedAgents) {
      graphComment = "graph: " + classifyRigidity(makeFormation(s)).summary();
    }
    const std::string scattered = applyDeploymentFlags(args, seed, s);  // --scatter, --safety

    // The core's rank test, run once (an SVD: seconds at a few hundred agents). Every shape
    // has n >= d + 1 agents, where rigidity is rank R = dn - d(d+1)/2.
    const Formation formation = makeFormation(s);
    const int rank = formation.rigidityRank(s.desiredPositions);
    const int needed = rigidEdgeCount(s.dimension, s.agentCount());
    if (rank != needed) {
      throw InvalidInput("--shape " + shape + ": the generated graph is not infinitesimally rigid (rigidity rank " +
                         std::to_string(rank) + ", need " + std::to_string(needed) +
                         (shape == "ring" ? "); use --chords 1 or more" : ")"));
    }
    s.timeStep = chooseTimeStep(args, formation, s, err);

    std::ostringstream yaml;
    const bool minimal = static_cast<int>(s.edges.size()) == needed;
    std::vector<std::string> comments = {"Generated by: " + commandLine(argc, argv),
                       g.description + ", spacing " + number(spacing) + " m: " +
                           std::to_string(s.agentCount()) + " agents, " +
                           std::to_string(s.edges.size()) + " edges, infinitesimally rigid (rank " +
                           std::to_string(rank) + ")" + (minimal ? ", minimally rigid" : ""),
                       !scattered.empty() ? scattered
                                          : "start: desired + uniform noise on [-" + number(sigma) + ", " +
                                                number(sigma) + "] per coordinate, seed " + std::to_string(seed)};
    if (!graphComment.empty()) comments.push_back(graphComment);
    writeScenarioYaml(s, comments, yaml);
    return writeOutput(args, yaml.str(), "make_scenario", out, err);
  } catch (const InvalidInput& e) {
    err << "make_scenario: error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::exception& e) {
    err << "make_scenario: error: " << e.what() << '\n';
    return kExitFailure;
  }
}

}  // namespace vf
