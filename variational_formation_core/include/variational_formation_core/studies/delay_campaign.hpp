#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "variational_formation_core/integrators/delayed_variational_integrator.hpp"
#include "variational_formation_core/model/scenario.hpp"

namespace vf {

/// Settings shared by every simulation of a delay x loss campaign.
struct DelayCampaignSettings {
  double timeStep = 0.0;     ///< h [s]
  double dampingGain = 0.0;  ///< kappa [1/s]
  long steps = 0;            ///< updates per simulation
  int runs = 16;             ///< simulations per (D, P) cell
  /// Every start coordinate is q* + perturbation * l_min * u, u uniform in [-1, 1), l_min the
  /// shortest desired edge [relative].
  double perturbation = 0.05;
  std::uint64_t seed = 1;    ///< seeds the starts (run r: seed + r) and the loss patterns
  double tolerance = 0.01;   ///< congruence: relative pair-distance tolerance (as roa)
  double maxSpeed = 0.1;     ///< congruence: speed bound [m/s] (as roa)
  double divergenceBound = 1e6;  ///< |coordinate| beyond which a run counts as diverged [m]
};

/// What one simulation ended as.
struct DelayRun {
  bool congruent = false;   ///< congruent at the last step
  long congruentStep = -1;  ///< earliest step from which it stays congruent, or -1
  bool diverged = false;
  long offered = 0;         ///< neighbour states offered
  long lost = 0;            ///< of which lost
};

/// One (D, P) cell of the campaign.
struct DelayCell {
  long delaySteps = 0;
  double loss = 0.0;
  std::vector<DelayRun> runs;
  double congruentFraction() const;
  /// Median congruentStep over the congruent runs, -1 if none.
  double medianCongruentStep() const;
};

/**
 * Delay x loss campaign (doc/delay_margin.md): per cell, `runs` simulations of
 * DelayedVariationalIntegrator from seeded small perturbations of the desired shape at rest,
 * with congruence (Formation::isCongruent, v_k = (q_k - q_{k-1})/h) checked at every step.
 * Run r starts from the same point in every cell, and its loss pattern has seed
 * seed + r + 1000003 (so P = 0 and D are the only differences between cells).
 */
class DelayCampaign {
 public:
  /// @throws InvalidInput on bad settings or a formation without edges.
  DelayCampaign(const Scenario& scenario, const DelayCampaignSettings& settings);

  Positions initialPositions(int run) const;
  DelayRun simulate(long delaySteps, double loss, int run) const;
  /// Every cell delays x losses on `threads` threads (results do not depend on the count).
  /// @param progress called with runs done, see parallelFor.
  std::vector<DelayCell> run(const std::vector<long>& delays, const std::vector<double>& losses,
                             int threads, const std::function<void(long)>& progress = {}) const;
  const Formation& formation() const { return formation_; }
  const DelayCampaignSettings& settings() const { return settings_; }

 private:
  Formation formation_;
  DelayCampaignSettings settings_;
  double shortestEdge_ = 0.0;
};

/**
 * The simulated margin: the largest swept D whose loss-free cell, and every loss-free cell of
 * smaller D, has a congruent fraction >= threshold. -1 if D = 0 fails or no loss-free cell.
 */
long simulatedDelayMargin(const std::vector<DelayCell>& cells, double threshold = 0.5);

}  // namespace vf
