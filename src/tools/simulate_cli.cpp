#include "variational_formation/tools/simulate_cli.hpp"

#include <fstream>
#include <ostream>

#include "variational_formation/core/error.hpp"
#include "variational_formation/core/simulation.hpp"
#include "variational_formation/tools/arguments.hpp"

namespace vf {

namespace {

const char* kUsage =
    "usage: simulate --scenario FILE --out traj.csv [--metrics metrics.csv]\n"
    "                [--method vi|euler|rk4] [--init variational|paper (vi only)]\n"
    "                [--time-step H] [--steps N] [--kappa K]\n"
    "Runs a formation scenario centrally. traj.csv: step,t,agent,x,y,z;\n"
    "metrics.csv: step,t,energy,max_distance_error,px,py,pz,ax,ay,az.\n"
    "Flags override the scenario file. Exit status 2 on bad input, 1 if the run diverges.\n";

std::ofstream openOutput(const std::string& flag, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw InvalidInput(flag + ": cannot write '" + path + "'");
  return out;
}

}  // namespace

int runSimulateCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  try {
    const Arguments args(argc, argv,
                         {{"--scenario", 1}, {"--out", 1}, {"--metrics", 1}, {"--method", 1},
                          {"--init", 1}, {"--time-step", 1}, {"--steps", 1}, {"--kappa", 1},
                          {"--help", 0}, {"-h", 0}});
    if (args.has("--help") || args.has("-h")) {
      out << kUsage;
      return kExitOk;
    }
    args.require("--scenario");
    args.require("--out");
    const Method method = parseMethod(args.text("--method", "vi"));
    const StartMethod start = parseStartMethod(args.text("--init", "variational"));
    if (args.has("--init") && method != Method::Variational) {
      throw InvalidInput("--init: only for --method vi (euler and rk4 start from v_0 directly), got --method " +
                         args.text("--method"));
    }
    Scenario scenario = loadScenario(args.text("--scenario"));
    applyOverrides(scenario, scenarioOverrides(args), /*requireBoundedSteps=*/true);
    for (const std::string& w : scenario.warnings) err << "simulate: warning: " << w << '\n';

    std::ofstream traj = openOutput("--out", args.text("--out"));
    std::ofstream metrics;
    const bool withMetrics = args.has("--metrics");
    if (withMetrics) metrics = openOutput("--metrics", args.text("--metrics"));
    writeTrajectoryHeader(traj);
    if (withMetrics) writeMetricsHeader(metrics);
    long divergedAt = -1;
    runScenario(scenario, method, start, [&](const Integrator& integrator) {
      writeTrajectoryRows(traj, integrator.stepIndex(), integrator.time(),
                          integrator.positions());
      if (withMetrics) writeMetricsRow(metrics, measure(integrator));
      if (divergedAt < 0 && !integrator.positions().allFinite()) {
        divergedAt = integrator.stepIndex();
      }
    });
    traj.flush();
    if (withMetrics) metrics.flush();
    if (!traj || (withMetrics && !metrics)) {
      err << "simulate: error: writing the output failed (disk full?)\n";
      return kExitFailure;
    }
    if (divergedAt >= 0) {
      err << "simulate: error: the run diverged: non-finite positions from step " << divergedAt
          << " (try a smaller --time-step)\n";
      return kExitFailure;
    }
    return kExitOk;
  } catch (const InvalidInput& e) {
    err << "simulate: error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::exception& e) {
    err << "simulate: error: " << e.what() << '\n';
    return kExitFailure;
  }
}

}  // namespace vf
