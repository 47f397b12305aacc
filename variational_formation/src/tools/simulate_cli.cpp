#include "variational_formation/tools/simulate_cli.hpp"

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>
#include <ostream>

#include "variational_formation_core/integrators/delayed_variational_integrator.hpp"
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/shape_outcome.hpp"
#include "variational_formation_core/manoeuvres/commanded_frame.hpp"
#include "variational_formation_core/agents/run_tracker.hpp"
#include "variational_formation_core/agents/run_verdict.hpp"
#include "variational_formation_core/integrators/step_metrics.hpp"
#include "variational_formation/tools/arguments.hpp"
#include "variational_formation/tools/scenario_path.hpp"

namespace vf {

namespace {

const char* kUsage =
    "usage: simulate --scenario FILE|NAME [--out traj.csv] [--metrics metrics.csv]\n"
    "                [--method vi|euler|rk4] [--init variational|paper (vi only)]\n"
    "                [--time-step H] [--steps N] [--kappa K]\n"
    "                [--delay-steps D] [--loss P [--seed S]]   (vi only)\n"
    "                [--commands FILE.csv]   (vi only; replaces the scenario's manoeuvre)\n"
    "Runs a formation scenario centrally and says how it ended. traj.csv: step,t,agent,x,y,z;\n"
    "metrics.csv: step,t,energy,max_distance_error,px,py,pz,ax,ay,az,cvx,cvy,cvz,wx,wy,wz,scale_error,\n"
    "shape_error (and min_separation under a scenario's safety: filter). The last line on stdout says\n"
    "how the formation ended: 'formation: converged to the desired shape ...' or 'formation: not\n"
    "converged' with why: its mirror image, folded, still settling at the last step, its final\n"
    "max distance error, or blocked; with `assignment: auto` a line 'assignment: ...' comes first,\n"
    "and with safety: a line 'simulate: safety: ...' before the last gives the closest approach.\n"
    "--commands: rows step,vx,vy,vz,wx,wy,wz,scale, each applying from its step on\n"
    "(doc/manoeuvres.md).\n"
    "Flags override the scenario file. --delay-steps D: each agent uses its neighbours'\n"
    "q_j^{k-D}; --loss P: each neighbour state is lost with probability P (seed S, default 1).\n"
    "Exit status 2 on bad input, 1 if the run diverges, or if the scenario has\n"
    "require_convergence: true and the formation did not converge (blocked runs included).\n";

std::ofstream openOutput(const std::string& flag, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw InvalidInput(flag + ": cannot write '" + path + "'");
  return out;
}

/// The delayed/lossy model's flags: true (and `delay` filled) if any is given.
bool parseDelayFlags(const Arguments& args, Method method, DelaySettings& delay) {
  if (!args.has("--delay-steps") && !args.has("--loss")) {
    if (args.has("--seed")) throw InvalidInput("--seed: only with --loss");
    return false;
  }
  if (method != Method::Variational) {
    throw InvalidInput(std::string(args.has("--loss") ? "--loss" : "--delay-steps") +
                       ": only with --method vi, got --method " + args.text("--method"));
  }
  if (args.has("--delay-steps")) delay.delaySteps = args.integer("--delay-steps", 0, 1000000);
  if (args.has("--loss")) {
    delay.lossProbability = args.number("--loss");
    if (delay.lossProbability < 0.0 || delay.lossProbability > 1.0) {
      throw InvalidInput("--loss: must be a probability in [0, 1], got " + args.text("--loss"));
    }
  }
  if (args.has("--seed")) {
    if (!args.has("--loss")) throw InvalidInput("--seed: only with --loss");
    delay.seed = static_cast<std::uint64_t>(
        args.integer("--seed", 0, std::numeric_limits<long>::max()));
  }
  return true;
}

/// The safety filter's line of a tracked run: the closest approach and how often the filter bound
/// (the shape's verdict, blocked or not, is the last line's alone).
void reportSafety(const RunTracker& tracker, std::ostream& out) {
  const ClosestPair& c = tracker.closestApproach();
  char distance[32];
  std::snprintf(distance, sizeof distance, "%.4g", c.distance);
  out << "simulate: safety: closest approach " << distance << " m";
  if (c.first >= 0) out << " (agents " << c.first << ", " << c.second << " at step " << tracker.closestApproachStep() << ")";
  out << "; filter active in " << tracker.filterActiveSteps() << " steps\n";
}

}  // namespace

int runSimulateCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  try {
    const Arguments args(argc, argv,
                         {{"--scenario", 1}, {"--out", 1}, {"--metrics", 1}, {"--method", 1},
                          {"--init", 1}, {"--time-step", 1}, {"--steps", 1}, {"--kappa", 1},
                          {"--delay-steps", 1}, {"--loss", 1}, {"--seed", 1}, {"--commands", 1},
                          {"--help", 0}, {"-h", 0}});
    if (args.has("--help") || args.has("-h")) {
      out << kUsage;
      return kExitOk;
    }
    args.require("--scenario");
    const Method method = parseMethod(args.text("--method", "vi"));
    const StartMethod start = parseStartMethod(args.text("--init", "variational"));
    if (args.has("--init") && method != Method::Variational) {
      throw InvalidInput("--init: only for --method vi (euler and rk4 start from v_0 directly), got --method " +
                         args.text("--method"));
    }
    DelaySettings delay;
    const bool delayed = parseDelayFlags(args, method, delay);
    Scenario scenario = loadScenario(resolveScenario(args.text("--scenario")));
    applyOverrides(scenario, scenarioOverrides(args), /*requireBoundedSteps=*/true);
    // A manoeuvre (the scenario's schedule, or --commands instead of it) runs the forced update.
    const bool manoeuvre = args.has("--commands") || !scenario.manoeuvre.empty();
    CommandSchedule schedule;
    if (manoeuvre) {
      const std::string what = args.has("--commands") ? "--commands" : "manoeuvre";
      if (method != Method::Variational) {
        throw InvalidInput(what + ": only with --method vi, got --method " + args.text("--method"));
      }
      if (delayed) throw InvalidInput(what + ": not with --delay-steps or --loss");
      schedule = args.has("--commands") ? loadCommands(args.text("--commands"), scenario)
                                        : scheduleFromSegments(scenario.manoeuvre, scenario.timeStep);
    }
    if (scenario.safety && delayed) throw InvalidInput("safety: not with --delay-steps or --loss");
    checkSafetyMethod(scenario, method);
    for (const std::string& w : scenario.warnings) err << "simulate: warning: " << w << '\n';
    if (scenario.autoAssignment) out << "assignment: " << scenario.assignment.describe() << '\n';

    // Without --out only the lines on stdout: how the run ended.
    std::ofstream traj, metrics;
    const bool withTrajectory = args.has("--out"), withMetrics = args.has("--metrics");
    if (withTrajectory) traj = openOutput("--out", args.text("--out"));
    if (withMetrics) metrics = openOutput("--metrics", args.text("--metrics"));
    if (withTrajectory) writeTrajectoryHeader(traj);
    const bool safety = scenario.safety.has_value();
    if (withMetrics) writeMetricsHeader(metrics, safety);
    long divergedAt = -1;
    const Formation formation = makeFormation(scenario);
    ShapeTracker shape(formation, scenario.mirrorAllowed);
    // Under a safety filter: the closest approach, the filter's activity, and a blocked run ends.
    std::unique_ptr<RunTracker> tracker;
    if (safety) tracker = std::make_unique<RunTracker>(scenario, schedule);
    // The first non-finite step is written (traj.csv shows it) and ends the run: nothing after it
    // means anything, and no check of the run is made on it.
    const auto observe = [&](const Integrator& integrator) {
      const long k = integrator.stepIndex();
      if (withTrajectory) writeTrajectoryRows(traj, integrator.stepIndex(), integrator.time(), integrator.positions());
      if (withMetrics) {
        writeMetricsRow(metrics, measure(integrator, shapeErrorMeasuredAt(k, formation.agentCount(), scenario.steps)),
                        safety);
      }
      if (!integrator.positions().allFinite()) {
        divergedAt = k;
        return false;
      }
      Velocities v = integrator.velocities();
      if (manoeuvre) subtractCommandedMotion(schedule.at(k > 0 ? k - 1 : 0), integrator.positions(), v);
      shape.observe(k, integrator.positions(), v, integrator.commandedScale());
      return !tracker || tracker->observe(integrator);
    };
    if (delayed) {
      runDelayedScenario(scenario, start, delay, observe);
    } else {
      runCentralised(scenario, method, start, manoeuvre ? &schedule : nullptr, observe);
    }
    if (withTrajectory) traj.flush();
    if (withMetrics) metrics.flush();
    if ((withTrajectory && !traj) || (withMetrics && !metrics)) {
      err << "simulate: error: writing the output failed (disk full?)\n";
      return kExitFailure;
    }
    if (divergedAt >= 0) {
      err << "simulate: error: the run diverged: non-finite positions from step " << divergedAt
          << " (try a smaller --time-step)\n";
      return kExitFailure;
    }
    if (tracker) reportSafety(*tracker, out);
    // One verdict: the shape's, or blocked; the exit status follows from it alone.
    const std::string blocked = tracker ? tracker->blockedBy() : std::string();
    const ShapeOutcome shaped = shape.outcome(scenario.timeStep);
    const ShapeOutcome outcome = blocked.empty() ? shaped : blockedShapeOutcome(shaped, blocked);
    out << "formation: " << outcome.line << '\n';
    const RunVerdict verdict = finishedRunVerdict(scenario, outcome);
    if (verdict.succeeded) return kExitOk;
    err << "simulate: error: " << verdict.reason << '\n';
    return kExitFailure;
  } catch (const InvalidInput& e) {
    err << "simulate: error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::exception& e) {
    err << "simulate: error: " << e.what() << '\n';
    return kExitFailure;
  }
}

}  // namespace vf
