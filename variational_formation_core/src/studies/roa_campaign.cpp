#include "variational_formation_core/studies/roa_campaign.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/validation.hpp"
#include "variational_formation_core/common/parallel.hpp"
#include "variational_formation_core/integrators/variational_integrator.hpp"

namespace vf {

RoaCampaign::RoaCampaign(const Scenario& scenario, const RoaGrid& grid, const RoaSettings& settings)
    : model_(std::make_shared<const Formation>(makeFormation(scenario))),
      formation_(model_.formation()),
      grid_(grid),
      settings_(settings),
      coefficients_(settings.timeStep, settings.dampingGain) {
  const int n = formation_.agentCount();
  if (grid.agent < 0 || grid.agent >= n) {
    throw InvalidInput("--agent: must be an agent id 0.." + std::to_string(n - 1) + ", got " +
                       std::to_string(grid.agent));
  }
  if (grid.nx < 1 || grid.ny < 1) throw InvalidInput("--resolution: must be >= 1 per axis");
  if (static_cast<long long>(grid.nx) * grid.ny > 100000000LL) {
    throw InvalidInput("--resolution: at most 1e8 cells");
  }
  for (double v : {grid.xMin, grid.xMax, grid.yMin, grid.yMax, grid.z}) {
    if (!std::isfinite(v)) throw InvalidInput("--x-range/--y-range/--z: values must be finite");
  }
  if (grid.xMin > grid.xMax) throw InvalidInput("--x-range: A must be <= B");
  if (grid.yMin > grid.yMax) throw InvalidInput("--y-range: C must be <= D");
  // The same checks as a scenario's, under the names of the roa flags that set these values.
  const FieldNames flags{"--kappa", "--time-step", "--steps"};
  validateDynamics(settings.timeStep, settings.dampingGain, flags);
  validateSteps(settings.steps, /*requireBounded=*/true, flags.steps);
  if (!(settings.tolerance > 0.0 && std::isfinite(settings.tolerance))) {
    throw InvalidInput("--tolerance: must be finite and > 0");
  }
  if (!(settings.maxSpeed > 0.0 && std::isfinite(settings.maxSpeed))) {
    throw InvalidInput("--speed: must be finite and > 0");
  }
  const Positions& shape = formation_.desiredShape();
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      // The same expression as Formation::isCongruent.
      desiredPairDistance_.push_back((shape.col(i) - shape.col(j)).norm());
    }
  }
}

RoaCell RoaCampaign::cellAt(int cell) const {
  RoaCell c;
  c.ix = cell % grid_.nx;
  c.iy = cell / grid_.nx;
  c.x = grid_.x(c.ix);
  c.y = grid_.y(c.iy);
  return c;
}

Positions RoaCampaign::initialPositions(int cell) const {
  const RoaCell c = cellAt(cell);
  Positions q0 = formation_.desiredShape();
  q0(0, grid_.agent) = c.x;
  q0(1, grid_.agent) = c.y;
  if (formation_.dimension() == 3) q0(2, grid_.agent) = grid_.z;
  return q0;
}

namespace {
bool escaped(const Positions& q, double bound) {
  for (Eigen::Index k = 0; k < q.size(); ++k) {
    if (!(std::abs(q.data()[k]) <= bound)) return true;  // also catches NaN
  }
  return false;
}
}  // namespace

RoaCell RoaCampaign::simulateCell(int cell) const {
  RoaCell result = cellAt(cell);
  const Positions q0 = initialPositions(cell);
  VariationalIntegrator vi(formation_, q0, Positions::Zero(q0.rows(), q0.cols()),
                           settings_.timeStep, settings_.dampingGain, StartMethod::Variational);
  vi.forceModel() = model_;  // the batched path's forces
  long lastIncongruent = -1;
  bool congruent = false;
  for (long k = 0; k <= settings_.steps; ++k) {
    if (k > 0) vi.step();
    if (escaped(vi.positions(), settings_.divergenceBound)) {
      result.diverged = true;
      return result;
    }
    congruent = formation_.isCongruent(vi.positions(), vi.velocities(), settings_.tolerance,
                                       settings_.maxSpeed);
    if (!congruent) lastIncongruent = k;
  }
  result.converged = congruent;
  result.convergedStep = congruent ? lastIncongruent + 1 : -1;
  return result;
}

Positions RoaCampaign::finalPositionsOfCell(int cell) const {
  const Positions q0 = initialPositions(cell);
  VariationalIntegrator vi(formation_, q0, Positions::Zero(q0.rows(), q0.cols()),
                           settings_.timeStep, settings_.dampingGain, StartMethod::Variational);
  vi.forceModel() = model_;
  for (long k = 0; k < settings_.steps; ++k) vi.step();
  return vi.positions();
}

namespace {

constexpr int kLanes = RoaCampaign::kLanes;

// kLanes simulations side by side in structure-of-arrays form: coordinate a of agent i in lane l
// is at [(i d + a) kLanes + l], so that every inner loop runs over the lanes.
struct LaneState {
  LaneState(int agents, int dimension)
      : agents(agents), dimension(dimension), stride(agents * dimension * kLanes),
        buffer(4 * static_cast<std::size_t>(stride), 0.0) {
    qPrev = buffer.data();
    q = qPrev + stride;
    qNext = q + stride;
    gradient = qNext + stride;
    for (int l = 0; l < kLanes; ++l) {
      lastIncongruent[l] = -1;
      diverged[l] = false;
      congruent[l] = false;
    }
  }

  int agents, dimension;
  int stride;                  // doubles per set of positions
  std::vector<double> buffer;  // the four sets below
  double* qPrev;               // q_{k-1}
  double* q;                   // q_k
  double* qNext;               // q_{k+1}, being computed
  double* gradient;            // grad V(q_k)
  long lastIncongruent[kLanes];
  bool diverged[kLanes];
  bool congruent[kLanes];
};

// q_{k+1} from q_k (and q_{k-1}) with the operations of variationalStart (k = 0, v_0 = 0) and
// variationalUpdate, then shifts the window so that q holds step k + 1.
void advance(const VariationalCoefficients& c, long k, LaneState& s) {
  const double* const qPrev = s.qPrev;
  const double* const q = s.q;
  const double* const g = s.gradient;
  double* const qNext = s.qNext;
  if (k == 0) {
    for (int x = 0; x < s.stride; ++x) {
      qNext[x] = q[x] + c.startGain * (0.0 - 0.5 * c.timeStep * g[x]);
    }
  } else {
    for (int x = 0; x < s.stride; ++x) {
      qNext[x] = c.positionGain * q[x] - c.decay * qPrev[x] - c.gradientGain * g[x];
    }
  }
  std::swap(s.qPrev, s.q);
  std::swap(s.q, s.qNext);
}

// Marks lanes with a coordinate beyond `bound` (or NaN) at the current step; true once every
// lane has diverged.
bool markDiverged(double bound, LaneState& s) {
  bool allDiverged = true;
  for (int l = 0; l < kLanes; ++l) {
    if (s.diverged[l]) continue;
    for (int x = l; x < s.stride; x += kLanes) {
      if (!(std::abs(s.q[x]) <= bound)) {
        s.diverged[l] = true;
        break;
      }
    }
    allDiverged = allDiverged && s.diverged[l];
  }
  return allDiverged;
}

// Congruence at step k as Formation::isCongruent tests it, v_k = (q_k - q_{k-1})/h: every speed
// below maxSpeed and every pair distance within tolerance of the desired one.
void markCongruent(long k, double h, double tolerance, double maxSpeed,
                   const std::vector<double>& desiredPairDistance, LaneState& s) {
  const int n = s.agents, d = s.dimension;
  const double* const q = s.q;
  const double* const qPrev = s.qPrev;
  double ok[kLanes];
  for (int l = 0; l < kLanes; ++l) ok[l] = 1.0;
  for (int i = 0; i < n; ++i) {
    double speed2[kLanes];
    for (int l = 0; l < kLanes; ++l) speed2[l] = 0.0;
    for (int a = 0; a < d; ++a) {
      for (int l = 0; l < kLanes; ++l) {
        const int x = (i * d + a) * kLanes + l;
        const double v = (q[x] - qPrev[x]) / h;
        speed2[l] += v * v;
      }
    }
    for (int l = 0; l < kLanes; ++l) ok[l] = std::sqrt(speed2[l]) < maxSpeed ? ok[l] : 0.0;
  }
  // The O(n^2) pair test only matters for lanes that pass the O(n) speed test.
  bool anySlow = false;
  for (int l = 0; l < kLanes; ++l) anySlow = anySlow || ok[l] != 0.0;
  int pair = 0;
  for (int i = 0; i < n && anySlow; ++i) {
    for (int j = i + 1; j < n; ++j, ++pair) {
      const double desired = desiredPairDistance[pair];
      double dist2[kLanes];
      for (int l = 0; l < kLanes; ++l) dist2[l] = 0.0;
      for (int a = 0; a < d; ++a) {
        for (int l = 0; l < kLanes; ++l) {
          const double diff = q[(i * d + a) * kLanes + l] - q[(j * d + a) * kLanes + l];
          dist2[l] += diff * diff;
        }
      }
      for (int l = 0; l < kLanes; ++l) {
        ok[l] = std::abs(std::sqrt(dist2[l]) - desired) <= tolerance * desired ? ok[l] : 0.0;
      }
    }
  }
  for (int l = 0; l < kLanes; ++l) {
    s.congruent[l] = ok[l] != 0.0;
    if (!s.congruent[l]) s.lastIncongruent[l] = k;
  }
}

// Starts lane l at rest at q0 (d x n): q_{-1} = q_0.
void setLane(const Positions& q0, int l, LaneState& s) {
  for (int i = 0; i < s.agents; ++i) {
    for (int a = 0; a < s.dimension; ++a) {
      const int x = (i * s.dimension + a) * kLanes + l;
      s.q[x] = s.qPrev[x] = q0(a, i);
    }
  }
}

// Lane l's current positions as d x n.
Positions lanePositions(const LaneState& s, int l) {
  Positions p(s.dimension, s.agents);
  for (int i = 0; i < s.agents; ++i)
    for (int a = 0; a < s.dimension; ++a) p(a, i) = s.q[(i * s.dimension + a) * kLanes + l];
  return p;
}

}  // namespace

// The batched kernel: per lane, the operations of VariationalIntegrator::step and the
// congruence test of simulateCell, in the same order, so the positions are bit-identical.
void RoaCampaign::simulateBatch(int first, int count, RoaCell* out,
                                std::vector<Positions>* finalPositions) const {
  LaneState lanes(formation_.agentCount(), formation_.dimension());
  for (int l = 0; l < kLanes; ++l) {
    // Idle lanes repeat the batch's last cell so that they stay finite.
    setLane(initialPositions(first + std::min(l, count - 1)), l, lanes);
  }
  for (long k = 0; k <= settings_.steps; ++k) {
    if (k > 0) {
      model_.laneGradient<kLanes>(lanes.q, lanes.gradient);  // grad V(q_k), the force model's fast path
      advance(coefficients_, k - 1, lanes);
    }
    if (markDiverged(settings_.divergenceBound, lanes)) break;
    markCongruent(k, settings_.timeStep, settings_.tolerance, settings_.maxSpeed,
                  desiredPairDistance_, lanes);
  }
  for (int l = 0; l < count; ++l) {
    RoaCell cell = cellAt(first + l);
    cell.diverged = lanes.diverged[l];
    cell.converged = !lanes.diverged[l] && lanes.congruent[l];
    cell.convergedStep = cell.converged ? lanes.lastIncongruent[l] + 1 : -1;
    out[l] = cell;
    if (finalPositions) finalPositions->push_back(lanePositions(lanes, l));
  }
}

std::vector<RoaCell> RoaCampaign::run(int threads, const std::function<void(long)>& progress) const {
  const int cells = cellCount();
  std::vector<RoaCell> results(static_cast<std::size_t>(cells));
  const int batches = (cells + kLanes - 1) / kLanes;
  const auto count = [&](int b) { return std::min(kLanes, cells - b * kLanes); };
  parallelFor(
      batches, threads,
      [&](int b) { simulateBatch(b * kLanes, count(b), &results[static_cast<std::size_t>(b * kLanes)]); },
      [&](int b) { return static_cast<long>(count(b)); }, progress);
  return results;
}

}  // namespace vf
