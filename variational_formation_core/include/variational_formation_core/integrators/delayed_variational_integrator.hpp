#pragma once

#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include "variational_formation_core/integrators/integrator.hpp"
#include "variational_formation_core/model/scenario.hpp"

namespace vf {

/// Seed of the loss pattern when none is given.
constexpr std::uint64_t kDefaultLossSeed = 1;

/// Communication faults of the delayed model (doc/delay_margin.md).
struct DelaySettings {
  long delaySteps = 0;            ///< D >= 0: agent i uses its neighbours' q_j^{k-D}
  double lossProbability = 0.0;   ///< P in [0, 1]: each state j -> i of each step is lost
  std::uint64_t seed = kDefaultLossSeed;  ///< seed of the loss pattern (std::mt19937_64)
};

/// @throws InvalidInput naming --delay-steps / --loss.
void validateDelaySettings(const DelaySettings& settings);

/**
 * Loss draws of the delayed model: std::mt19937_64 (its output sequence is fixed by the C++
 * standard) and a uniform u = (x >> 11) 2^-53 in [0, 1) formed here, not by a standard-library
 * distribution, so a seed gives the same pattern everywhere. A message is lost iff u < P.
 */
class LossPattern {
 public:
  LossPattern(double probability, std::uint64_t seed) : probability_(probability), engine_(seed) {}
  bool lost();
  long draws() const { return draws_; }
  long losses() const { return losses_; }

 private:
  double probability_;
  std::mt19937_64 engine_;
  long draws_ = 0;
  long losses_ = 0;
};

/**
 * The variational integrator with delayed and lossy neighbour states (doc/delay_margin.md):
 * agent i computes q_i^{k+1} from its own q_i^k, q_i^{k-1} and, for each neighbour j, the newest
 * q_j^m it received with m <= k - D (q_j^0, known from the scenario, when there is none). The
 * state q_j^m (m >= 1) of edge j -> i is lost with probability P, drawn when it would arrive
 * (step m + D), agent by agent and neighbour by neighbour in the order of
 * Formation::neighbours, so the draw of (m, j -> i) does not depend on D. The start step k = 0
 * is the ordinary one. Each agent's step calls agentGradient and variationalUpdate /
 * variationalStart as VariationalIntegrator does, on a view holding q_i^k and the neighbour
 * states, so D = 0 without loss reproduces VariationalIntegrator bit for bit.
 */
class DelayedVariationalIntegrator : public Integrator {
 public:
  /// @throws InvalidInput on bad settings.
  DelayedVariationalIntegrator(const Formation& formation, const Positions& q0, const Positions& v0,
                               double timeStep, double dampingGain, StartMethod start,
                               const DelaySettings& delay);

  void step() override;
  const Positions& positions() const override { return q_; }
  Positions velocities() const override;
  Positions momenta() const override;
  double energy() const override;

  const DelaySettings& delay() const { return delay_; }
  /// Neighbour states offered and lost so far.
  long offeredStates() const { return loss_.draws(); }
  long lostStates() const { return loss_.losses(); }

 private:
  VariationalCoefficients coefficients_;
  StartMethod start_;
  DelaySettings delay_;
  LossPattern loss_;
  Positions v0_, qPrev_, q_, qNext_, view_;
  std::vector<Positions> history_;  // q^m in slot m mod (D + 1)
  std::vector<std::vector<double>> held_;  // per agent, d doubles per neighbour in list order
};

/**
 * runScenario (simulation.hpp) with the delayed model: observe at steps 0..steps; the run ends
 * after a step at which `observe` returns false (a diverged one, in simulate).
 * @throws InvalidInput on bad settings or steps = 0.
 */
void runDelayedScenario(const Scenario& scenario, StartMethod start, const DelaySettings& delay,
                        const std::function<bool(const Integrator&)>& observe);

}  // namespace vf
