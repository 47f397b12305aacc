#include "variational_formation/tools/roa_cli.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <ostream>
#include <string>
#include <thread>
#include <vector>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/studies/roa_campaign.hpp"
#include "variational_formation/tools/arguments.hpp"
#include "variational_formation/tools/progress.hpp"
#include "variational_formation/tools/simulate_cli.hpp"
#include "variational_formation/tools/scenario_path.hpp"

namespace vf {

namespace {

const char* kUsage =
    "usage: roa --scenario FILE|NAME --agent I --x-range A B --y-range C D [--z Z]\n"
    "           --resolution NX NY [--time-step H] [--steps N] [--kappa K]\n"
    "           [--tolerance 0.01] [--speed 0.1] [--threads T] --out roa.csv\n"
    "Region of attraction (paper Section 6.2): for every grid point, agent I starts there at\n"
    "rest and the others at rest at their desired positions. roa.csv:\n"
    "ix,iy,x,y,converged,converged_step,diverged. --time-step, --steps and --kappa override\n"
    "the scenario and are checked like it. Exit status 2 on bad input.\n";

// --agent, --x-range, --y-range, --z (3D: default the agent's desired z), --resolution.
RoaGrid readGrid(const Arguments& args, const Scenario& scenario) {
  RoaGrid grid;
  grid.agent = static_cast<int>(args.integer("--agent", 0, scenario.agentCount() - 1));
  grid.xMin = args.number("--x-range", 0);
  grid.xMax = args.number("--x-range", 1);
  grid.yMin = args.number("--y-range", 0);
  grid.yMax = args.number("--y-range", 1);
  if (args.has("--z")) {
    if (scenario.dimension != 3) throw InvalidInput("--z: only for 3D scenarios");
    grid.z = args.number("--z");
  } else if (scenario.dimension == 3) {
    grid.z = scenario.desiredPositions(2, grid.agent);
  }
  grid.nx = static_cast<int>(args.integer("--resolution", 1, 100000, 0));
  grid.ny = static_cast<int>(args.integer("--resolution", 1, 100000, 1));
  return grid;
}

// h, kappa and steps of the scenario (its overrides applied and validated), --tolerance, --speed.
RoaSettings readSettings(const Arguments& args, const Scenario& scenario) {
  RoaSettings settings;
  settings.timeStep = scenario.timeStep;
  settings.dampingGain = scenario.dampingGain;
  settings.steps = scenario.steps;
  if (args.has("--tolerance")) settings.tolerance = args.positiveNumber("--tolerance");
  if (args.has("--speed")) settings.maxSpeed = args.positiveNumber("--speed");
  return settings;
}

int readThreads(const Arguments& args) {
  const int hardware = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return args.has("--threads") ? static_cast<int>(args.integer("--threads", 1, 1024)) : hardware;
}

// Runs the campaign (with a progress bar on a terminal); returns the cells and the seconds taken.
std::vector<RoaCell> runTimed(const RoaCampaign& campaign, int threads, std::ostream& err,
                              bool progressToTerminal, double& seconds) {
  const auto start = std::chrono::steady_clock::now();
  std::function<void(long)> progress;
  if (progressToTerminal) {
    progress = [&](long done) { drawProgressBar(err, done, campaign.cellCount()); };
  }
  std::vector<RoaCell> cells = campaign.run(threads, progress);
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (progressToTerminal) err << '\n';
  return cells;
}

// roa.csv rows, 17 significant digits.
void writeCells(std::ostream& csv, const std::vector<RoaCell>& cells) {
  csv << "ix,iy,x,y,converged,converged_step,diverged\n";
  char line[160];
  for (const RoaCell& c : cells) {
    std::snprintf(line, sizeof line, "%d,%d,%.17g,%.17g,%d,%ld,%d\n", c.ix, c.iy, c.x, c.y,
                  c.converged ? 1 : 0, c.convergedStep, c.diverged ? 1 : 0);
    csv << line;
  }
}

std::string summary(const std::vector<RoaCell>& cells, double seconds, int threads, long steps) {
  long converged = 0, diverged = 0;
  for (const RoaCell& c : cells) {
    converged += c.converged;
    diverged += c.diverged;
  }
  const double total = static_cast<double>(cells.size());
  char text[256];
  std::snprintf(text, sizeof text,
                "roa: %zu cells, converged %.1f%%, diverged %.1f%%, compute %.1f ms on %d "
                "threads, %.0f simulations/s (%ld steps each)\n",
                cells.size(), 100.0 * converged / total, 100.0 * diverged / total, 1e3 * seconds,
                threads, total / std::max(seconds, 1e-9), steps);
  return text;
}

}  // namespace

int runRoaCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err,
              bool progressToTerminal) {
  try {
    const Arguments args(argc, argv,
                         {{"--scenario", 1}, {"--agent", 1}, {"--x-range", 2}, {"--y-range", 2},
                          {"--z", 1}, {"--resolution", 2}, {"--time-step", 1}, {"--steps", 1},
                          {"--kappa", 1}, {"--tolerance", 1}, {"--speed", 1}, {"--threads", 1},
                          {"--out", 1}, {"--help", 0}, {"-h", 0}});
    if (args.has("--help") || args.has("-h")) {
      out << kUsage;
      return kExitOk;
    }
    for (const char* flag : {"--scenario", "--agent", "--x-range", "--y-range", "--resolution", "--out"}) {
      args.require(flag);
    }
    Scenario scenario = loadScenario(resolveScenario(args.text("--scenario")));
    applyOverrides(scenario, scenarioOverrides(args), /*requireBoundedSteps=*/true);
    for (const std::string& w : scenario.warnings) err << "roa: warning: " << w << '\n';
    const RoaCampaign campaign(scenario, readGrid(args, scenario), readSettings(args, scenario));
    const int threads = readThreads(args);
    std::ofstream csv(args.text("--out"));
    if (!csv) throw InvalidInput("--out: cannot write '" + args.text("--out") + "'");

    double seconds = 0.0;
    const std::vector<RoaCell> cells = runTimed(campaign, threads, err, progressToTerminal, seconds);
    writeCells(csv, cells);
    csv.flush();
    if (!csv) {
      err << "roa: error: writing " << args.text("--out") << " failed\n";
      return kExitFailure;
    }
    // Diverged cells are a result of the campaign, not an error.
    out << summary(cells, seconds, threads, scenario.steps);
    return kExitOk;
  } catch (const InvalidInput& e) {
    err << "roa: error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::exception& e) {
    err << "roa: error: " << e.what() << '\n';
    return kExitFailure;
  }
}

}  // namespace vf
