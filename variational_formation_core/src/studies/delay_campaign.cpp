#include "variational_formation_core/studies/delay_campaign.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/parallel.hpp"

namespace vf {

double DelayCell::congruentFraction() const {
  if (runs.empty()) return 0.0;
  long n = 0;
  for (const DelayRun& r : runs) n += r.congruent ? 1 : 0;
  return static_cast<double>(n) / static_cast<double>(runs.size());
}

double DelayCell::medianCongruentStep() const {
  std::vector<long> steps;
  for (const DelayRun& r : runs) {
    if (r.congruent) steps.push_back(r.congruentStep);
  }
  if (steps.empty()) return -1.0;
  std::sort(steps.begin(), steps.end());
  const std::size_t m = steps.size() / 2;
  return steps.size() % 2 ? static_cast<double>(steps[m]) : 0.5 * static_cast<double>(steps[m - 1] + steps[m]);
}

DelayCampaign::DelayCampaign(const Scenario& scenario, const DelayCampaignSettings& settings)
    : formation_(makeFormation(scenario)), settings_(settings) {
  if (formation_.edges().empty()) {
    throw InvalidInput("edges: the formation has no edges, so no agent has a neighbour and a delay changes nothing");
  }
  if (!(std::isfinite(settings.timeStep) && settings.timeStep > 0.0)) {
    throw InvalidInput("--time-step: must be finite and > 0");
  }
  if (!(std::isfinite(settings.dampingGain) && settings.dampingGain >= 0.0)) {
    throw InvalidInput("--kappa: must be finite and >= 0");
  }
  if (settings.steps < 1) throw InvalidInput("--steps: must be >= 1");
  if (settings.runs < 1) throw InvalidInput("--runs: must be >= 1");
  if (!(std::isfinite(settings.perturbation) && settings.perturbation >= 0.0)) {
    throw InvalidInput("--perturbation: must be finite and >= 0");
  }
  shortestEdge_ = formation_.edges().front().desiredDistance;
  for (const Edge& e : formation_.edges()) shortestEdge_ = std::min(shortestEdge_, e.desiredDistance);
}

Positions DelayCampaign::initialPositions(int run) const {
  std::mt19937_64 engine(settings_.seed + static_cast<std::uint64_t>(run));
  Positions q0 = formation_.desiredShape();
  const double amplitude = settings_.perturbation * shortestEdge_;
  for (Eigen::Index k = 0; k < q0.size(); ++k) {
    const double u = static_cast<double>(engine() >> 11) * 0x1.0p-53;  // [0, 1), as LossPattern
    q0.data()[k] += amplitude * (2.0 * u - 1.0);
  }
  return q0;
}

DelayRun DelayCampaign::simulate(long delaySteps, double loss, int run) const {
  DelaySettings delay;
  delay.delaySteps = delaySteps;
  delay.lossProbability = loss;
  delay.seed = settings_.seed + static_cast<std::uint64_t>(run) + 1000003u;
  const Positions q0 = initialPositions(run);
  DelayedVariationalIntegrator vi(formation_, q0, Positions::Zero(q0.rows(), q0.cols()),
                                  settings_.timeStep, settings_.dampingGain,
                                  StartMethod::Variational, delay);
  DelayRun result;
  long lastIncongruent = -1;
  bool congruent = false;
  for (long k = 0; k <= settings_.steps; ++k) {
    if (k > 0) vi.step();
    const Positions& q = vi.positions();
    if (!(q.cwiseAbs().maxCoeff() <= settings_.divergenceBound)) {  // also NaN
      result.diverged = true;
      break;
    }
    congruent = formation_.isCongruent(q, vi.velocities(), settings_.tolerance, settings_.maxSpeed);
    if (!congruent) lastIncongruent = k;
  }
  result.congruent = !result.diverged && congruent;
  result.congruentStep = result.congruent ? lastIncongruent + 1 : -1;
  result.offered = vi.offeredStates();
  result.lost = vi.lostStates();
  return result;
}

std::vector<DelayCell> DelayCampaign::run(const std::vector<long>& delays,
                                          const std::vector<double>& losses, int threads,
                                          const std::function<void(long)>& progress) const {
  for (long D : delays) validateDelaySettings({D, 0.0, 1});
  for (double P : losses) validateDelaySettings({0, P, 1});
  const int runs = settings_.runs;
  std::vector<DelayCell> cells;
  for (long D : delays) {
    for (double P : losses) {
      DelayCell c;
      c.delaySteps = D;
      c.loss = P;
      c.runs.resize(static_cast<std::size_t>(runs));
      cells.push_back(c);
    }
  }
  const int tasks = static_cast<int>(cells.size()) * runs;
  parallelFor(
      tasks, threads,
      [&](int t) {
        DelayCell& c = cells[static_cast<std::size_t>(t / runs)];
        c.runs[static_cast<std::size_t>(t % runs)] = simulate(c.delaySteps, c.loss, t % runs);
      },
      {}, progress);
  return cells;
}

long simulatedDelayMargin(const std::vector<DelayCell>& cells, double threshold) {
  std::vector<const DelayCell*> lossFree;
  for (const DelayCell& c : cells) {
    if (c.loss == 0.0) lossFree.push_back(&c);
  }
  std::sort(lossFree.begin(), lossFree.end(),
            [](const DelayCell* a, const DelayCell* b) { return a->delaySteps < b->delaySteps; });
  long margin = -1;
  for (const DelayCell* c : lossFree) {
    if (c->congruentFraction() < threshold) break;
    margin = c->delaySteps;
  }
  return margin;
}

}  // namespace vf
