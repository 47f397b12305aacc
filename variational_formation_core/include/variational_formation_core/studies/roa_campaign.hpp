#pragma once

#include <atomic>
#include <functional>
#include <vector>

#include "variational_formation_core/model/force_model.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/integrators/variational_update.hpp"

namespace vf {

/// The grid of starting points of one agent (paper Section 6.2).
struct RoaGrid {
  int agent = 0;       ///< the agent placed at each grid point; the others start at q*
  double xMin = 0.0, xMax = 0.0, yMin = 0.0, yMax = 0.0;  ///< [m], world frame
  double z = 0.0;      ///< third coordinate in 3D scenarios [m]
  int nx = 1, ny = 1;  ///< points per axis (a single point sits at the minimum)

  double x(int ix) const { return nx > 1 ? xMin + (xMax - xMin) * ix / (nx - 1) : xMin; }
  double y(int iy) const { return ny > 1 ? yMin + (yMax - yMin) * iy / (ny - 1) : yMin; }
};

/// Congruence thresholds and run length of every simulation of a campaign.
struct RoaSettings {
  double timeStep = 0.0;     ///< h [s]
  double dampingGain = 0.0;  ///< kappa [1/s]
  long steps = 0;            ///< updates per simulation
  double tolerance = 0.01;   ///< relative pair-distance tolerance of the congruence test
  double maxSpeed = 0.1;     ///< speed bound of the congruence test [m/s]
  double divergenceBound = 1e6;  ///< |coordinate| beyond which a run counts as diverged [m]
};

/// What one simulation ended as.
struct RoaCell {
  int ix = 0, iy = 0;
  double x = 0.0, y = 0.0;
  bool converged = false;     ///< congruent at the last step
  long convergedStep = -1;    ///< earliest step from which the run stays congruent, or -1
  bool diverged = false;      ///< non-finite or beyond divergenceBound at some step
};

/**
 * Region-of-attraction campaign: one simulation per grid point, agent `grid.agent` starting
 * there at rest and every other agent at rest at its desired position; each run is the
 * variational integrator with the variational start. Congruence (doc/maths.md §8) is checked at
 * every step with v_k = (q_k - q_{k-1})/h.
 *
 * Two paths compute the same thing: simulateCell (one simulation over the core's
 * VariationalIntegrator and Formation::isCongruent) and the batched kernel that run() uses
 * (kLanes simulations side by side, structure of arrays, the same operations in the same
 * order), whose positions are bit-identical to the scalar path. Both take their forces from one
 * ForceModel: the scalar path through the integrator, the batched one through its fast path
 * ForceModel::laneGradient.
 */
class RoaCampaign {
 public:
  static constexpr int kLanes = 8;

  /// @throws InvalidInput on a bad agent index, grid or settings (h, kappa and steps through
  /// validateDynamics and validateSteps, named after the roa flags).
  RoaCampaign(const Scenario& scenario, const RoaGrid& grid, const RoaSettings& settings);

  int cellCount() const { return grid_.nx * grid_.ny; }
  const Formation& formation() const { return formation_; }
  const ForceModel& forceModel() const { return model_; }

  /// Runs every cell on `threads` threads (results do not depend on the thread count).
  /// @param progress called from the calling thread about every 100 ms with cells done.
  std::vector<RoaCell> run(int threads, const std::function<void(long)>& progress = {}) const;

  /// The plain path: one simulation over the core integrator.
  RoaCell simulateCell(int cell) const;
  /// The batched path for cells [first, first + count), count <= kLanes. If finalPositions is
  /// given it receives, per cell, the d x n positions at the last step.
  void simulateBatch(int first, int count, RoaCell* out,
                     std::vector<Positions>* finalPositions = nullptr) const;
  /// The scalar path's final positions, for comparison with simulateBatch.
  Positions finalPositionsOfCell(int cell) const;

 private:
  RoaCell cellAt(int cell) const;
  Positions initialPositions(int cell) const;

  ForceModel model_;  // owns the scenario's formation
  const Formation& formation_;
  RoaGrid grid_;
  RoaSettings settings_;
  VariationalCoefficients coefficients_;
  std::vector<double> desiredPairDistance_;  // i < j, row-major over i
};

}  // namespace vf
