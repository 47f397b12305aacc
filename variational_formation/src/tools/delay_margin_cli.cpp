#include "variational_formation/tools/delay_margin_cli.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <sstream>
#include <thread>

#include "variational_formation_core/studies/delay_campaign.hpp"
#include "variational_formation_core/studies/delay_margin.hpp"
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation/tools/arguments.hpp"
#include "variational_formation/tools/progress.hpp"
#include "variational_formation/tools/simulate_cli.hpp"
#include "variational_formation/tools/scenario_path.hpp"

namespace vf {

namespace {

const char* kUsage =
    "usage: delay_margin --scenario FILE|NAME --out-dir DIR [--kappa K] [--time-step H]\n"
    "           [--steps N] [--max-delay 30] [--delays A B] [--losses P1,P2,...]\n"
    "           [--runs 16] [--perturbation 0.05] [--seed S] [--threshold 0.5] [--threads T]\n"
    "Predicts the delay margin D* (largest D with every D' <= D locally stable; linearised\n"
    "delayed recurrence, companion matrix) and measures it: for every D in A..B (default\n"
    "0..min(D*+3, max-delay)) and loss P (default 0,0.2,0.5), --runs simulations from seeded\n"
    "perturbations of the desired shape (each coordinate within perturbation x shortest edge).\n"
    "Writes DIR/<name>_D<D>_P<P>.csv (run,congruent,congruent_step,diverged,lost,offered) and\n"
    "DIR/<name>_delay_margin.csv (one row per cell). Simulated margin: the largest D whose\n"
    "loss-free cell, and every one below it, has a congruent fraction >= threshold.\n"
    "Exit status 2 on bad input.\n";

std::vector<double> parseLosses(const std::string& text) {
  std::vector<double> losses;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    char* end = nullptr;
    const double p = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size() || !(p >= 0.0 && p <= 1.0)) {
      throw InvalidInput("--losses: each value must be a probability in [0, 1], got '" + item + "'");
    }
    losses.push_back(p);
  }
  if (losses.empty()) throw InvalidInput("--losses: give at least one probability");
  return losses;
}

std::string marginText(long margin, bool capped) {
  return capped ? ">= " + std::to_string(margin) : std::to_string(margin);
}

}  // namespace

int runDelayMarginCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err,
                      bool progressToTerminal) {
  try {
    const Arguments args(argc, argv,
                         {{"--scenario", 1}, {"--out-dir", 1}, {"--kappa", 1}, {"--time-step", 1},
                          {"--steps", 1}, {"--max-delay", 1}, {"--delays", 2}, {"--losses", 1},
                          {"--runs", 1}, {"--perturbation", 1}, {"--seed", 1}, {"--threshold", 1},
                          {"--threads", 1}, {"--help", 0}, {"-h", 0}});
    if (args.has("--help") || args.has("-h")) {
      out << kUsage;
      return kExitOk;
    }
    args.require("--scenario");
    args.require("--out-dir");
    Scenario scenario = loadScenario(resolveScenario(args.text("--scenario")));
    DelayCampaignSettings settings;
    settings.timeStep = args.has("--time-step") ? args.positiveNumber("--time-step") : scenario.timeStep;
    settings.dampingGain = args.has("--kappa") ? args.number("--kappa") : scenario.dampingGain;
    if (settings.dampingGain < 0.0) throw InvalidInput("--kappa: must be >= 0, got " + args.text("--kappa"));
    settings.steps = args.has("--steps") ? args.integer("--steps", 1, 100000000) : scenario.steps;
    if (settings.steps < 1) throw InvalidInput("--steps: the scenario has steps 0 (unbounded); give --steps N");
    if (args.has("--runs")) settings.runs = static_cast<int>(args.integer("--runs", 1, 100000));
    if (args.has("--perturbation")) settings.perturbation = args.positiveNumber("--perturbation");
    if (args.has("--seed")) settings.seed = static_cast<std::uint64_t>(args.integer("--seed", 0, 1L << 62));
    const double threshold = args.has("--threshold") ? args.number("--threshold") : 0.5;
    if (!(threshold > 0.0 && threshold <= 1.0)) throw InvalidInput("--threshold: must be in (0, 1]");
    const long maxDelay = args.has("--max-delay") ? args.integer("--max-delay", 0, 1000) : 30;
    const std::vector<double> losses = parseLosses(args.text("--losses", "0,0.2,0.5"));
    const int hardware = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    const int threads = args.has("--threads") ? static_cast<int>(args.integer("--threads", 1, 1024)) : hardware;
    const Formation formation = makeFormation(scenario);
    if (formation.edges().empty()) {
      out << "delay_margin: " << scenario.name
          << ": no edges, so no agent has a neighbour: a delay or a loss changes nothing (no margin)\n";
      return kExitOk;
    }
    const DelayCampaign campaign(scenario, settings);  // checks the settings before the scan
    // Made before the (long) scan and campaign, so that a bad directory fails at once.
    const std::string dir = args.text("--out-dir");
    std::error_code made;
    std::filesystem::create_directories(dir, made);
    if (made || !std::filesystem::is_directory(dir, made)) {
      throw InvalidInput("--out-dir: cannot create the directory '" + dir + "'" +
                         (made ? ": " + made.message() : std::string()));
    }

    const auto wallStart = std::chrono::steady_clock::now();
    const DelayMargin predicted =
        predictDelayMargin(formation, settings.timeStep, settings.dampingGain, maxDelay);
    std::vector<long> delays;
    const long first = args.has("--delays") ? args.integer("--delays", 0, 100000, 0) : 0;
    const long last = args.has("--delays") ? args.integer("--delays", 0, 100000, 1)
                                           : std::min(maxDelay, std::max(0L, predicted.margin) + 3);
    if (first > last) throw InvalidInput("--delays: A must be <= B");
    for (long D = first; D <= last; ++D) delays.push_back(D);

    const long total = static_cast<long>(delays.size() * losses.size()) * settings.runs;
    std::function<void(long)> progress;
    if (progressToTerminal) progress = [&](long done) { drawProgressBar(err, done, total); };
    const auto simStart = std::chrono::steady_clock::now();
    const std::vector<DelayCell> cells = campaign.run(delays, losses, threads, progress);
    const auto end = std::chrono::steady_clock::now();
    if (progressToTerminal) err << '\n';

    const std::string summaryPath = dir + "/" + scenario.name + "_delay_margin.csv";
    std::ofstream summary(summaryPath);
    if (!summary) throw InvalidInput("--out-dir: cannot write '" + summaryPath + "'");
    summary << "delay_steps,loss,runs,congruent_fraction,median_congruent_step,"
               "median_congruent_time,lost_fraction,predicted_margin,predicted_capped,"
               "unstable_roots\n";
    char line[256];
    for (const DelayCell& c : cells) {
      std::snprintf(line, sizeof line, "%s/%s_D%ld_P%g.csv", dir.c_str(), scenario.name.c_str(),
                    c.delaySteps, c.loss);
      std::ofstream csv(line);
      if (!csv) throw InvalidInput(std::string("--out-dir: cannot write '") + line + "'");
      csv << "run,congruent,congruent_step,diverged,lost,offered\n";
      long lost = 0, offered = 0;
      for (std::size_t r = 0; r < c.runs.size(); ++r) {
        const DelayRun& run = c.runs[r];
        csv << r << ',' << run.congruent << ',' << run.congruentStep << ',' << run.diverged << ','
            << run.lost << ',' << run.offered << '\n';
        lost += run.lost;
        offered += run.offered;
      }
      const std::size_t D = static_cast<std::size_t>(c.delaySteps);
      const int roots = D < predicted.unstableRoots.size() ? predicted.unstableRoots[D] : -1;
      const double median = c.medianCongruentStep();
      std::snprintf(line, sizeof line, "%ld,%g,%zu,%.6g,%.6g,%.6g,%.6g,%ld,%d,%d\n", c.delaySteps,
                    c.loss, c.runs.size(), c.congruentFraction(), median,
                    median < 0 ? -1.0 : median * settings.timeStep,
                    offered > 0 ? static_cast<double>(lost) / static_cast<double>(offered) : 0.0,
                    predicted.margin, predicted.capped ? 1 : 0, roots);
      summary << line;
    }
    summary.flush();
    if (!summary) {
      err << "delay_margin: error: writing " << summaryPath << " failed\n";
      return kExitFailure;
    }
    const long simulated = simulatedDelayMargin(cells, threshold);
    const bool simulatedCapped = simulated == delays.back();
    const double simSeconds = std::chrono::duration<double>(end - simStart).count();
    const double wallSeconds = std::chrono::duration<double>(end - wallStart).count();
    std::snprintf(line, sizeof line,
                  "delay_margin: %s (kappa %g, h %g): predicted margin D* = %s steps "
                  "(root count scan %.3f s), simulated margin = %s steps\n",
                  scenario.name.c_str(), settings.dampingGain, settings.timeStep,
                  marginText(predicted.margin, predicted.capped).c_str(), predicted.scanSeconds,
                  marginText(simulated, simulatedCapped).c_str());
    out << line;
    for (const DelaySpectrum& s : predicted.checks) {
      std::snprintf(line, sizeof line,
                    "delay_margin: companion matrix check D = %ld: spectral radius %.9f (%s), "
                    "%d fixed modes excluded (|lambda - 1| <= %.1e), %d eigenvalues at 1\n",
                    s.delaySteps, s.spectralRadius, s.stable() ? "stable" : "unstable",
                    s.fixedModes, s.excludedDistance, s.eigenvaluesAtOne);
      out << line;
    }
    if (!predicted.checks.empty()) {
      std::snprintf(line, sizeof line, "delay_margin: companion check %s (%.2f s)\n",
                    predicted.confirmed() ? "agrees" : "DISAGREES", predicted.checkSeconds);
      out << line;
    }
    std::snprintf(line, sizeof line,
                  "delay_margin: %zu cells x %d runs x %ld steps in %.2f s on %d threads; "
                  "wall time %.2f s; %s\n",
                  cells.size(), settings.runs, settings.steps, simSeconds, threads, wallSeconds,
                  summaryPath.c_str());
    out << line;
    return kExitOk;
  } catch (const InvalidInput& e) {
    err << "delay_margin: error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::exception& e) {
    err << "delay_margin: error: " << e.what() << '\n';
    return kExitFailure;
  }
}

}  // namespace vf
