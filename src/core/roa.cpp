#include "variational_formation/core/roa.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <thread>

#include "variational_formation/core/error.hpp"
#include "variational_formation/core/variational_integrator.hpp"

namespace vf {

namespace {
constexpr int L = RoaCampaign::kLanes;
}  // namespace

RoaCampaign::RoaCampaign(const Scenario& scenario, const RoaGrid& grid, const RoaSettings& settings)
    : formation_(makeFormation(scenario)),
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
  if (!(std::isfinite(settings.timeStep) && settings.timeStep > 0.0)) {
    throw InvalidInput("--time-step: must be finite and > 0");
  }
  if (!(std::isfinite(settings.dampingGain) && settings.dampingGain >= 0.0)) {
    throw InvalidInput("--kappa: must be finite and >= 0");
  }
  if (settings.steps < 1) throw InvalidInput("--steps: must be >= 1");
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
  for (long k = 0; k < settings_.steps; ++k) vi.step();
  return vi.positions();
}

// The batched kernel: kLanes simulations in structure-of-arrays form, x[(i d + a) L + lane].
// Per lane it performs the operations of VariationalIntegrator::step in the same order: the
// gradient is scattered edge by edge (agent j's terms arrive in the order of its neighbour
// list, and gamma (q_j - q_i) = -(gamma (q_i - q_j)) exactly), then the explicit update.
void RoaCampaign::simulateBatch(int first, int count, RoaCell* out,
                                std::vector<Positions>* finalPositions) const {
  const int n = formation_.agentCount();
  const int d = formation_.dimension();
  const int stride = n * d * L;
  std::vector<double> buffer(4 * static_cast<std::size_t>(stride), 0.0);
  double* qPrev = buffer.data();
  double* q = qPrev + stride;
  double* qNext = q + stride;
  double* g = qNext + stride;
  std::vector<Positions> starts;
  for (int l = 0; l < L; ++l) {
    // Idle lanes repeat the first cell so that they stay finite.
    const Positions q0 = initialPositions(first + std::min(l, count - 1));
    for (int i = 0; i < n; ++i)
      for (int a = 0; a < d; ++a) q[(i * d + a) * L + l] = q0(a, i);
  }
  std::copy(q, q + stride, qPrev);

  const auto& edges = formation_.edges();
  const VariationalCoefficients& c = coefficients_;
  const double h = settings_.timeStep;
  const double tol = settings_.tolerance;
  const double maxSpeed = settings_.maxSpeed;
  const double bound = settings_.divergenceBound;

  long lastIncongruent[L];
  bool diverged[L];
  bool congruent[L];
  for (int l = 0; l < L; ++l) {
    lastIncongruent[l] = -1;
    diverged[l] = false;
    congruent[l] = false;
  }

  for (long k = 0; k <= settings_.steps; ++k) {
    if (k > 0) {
      std::fill(g, g + stride, 0.0);
      for (const Edge& e : edges) {
        double* gi = g + e.tail * d * L;
        double* gj = g + e.head * d * L;
        const double* qi = q + e.tail * d * L;
        const double* qj = q + e.head * d * L;
        double gamma[L];
        for (int l = 0; l < L; ++l) gamma[l] = 0.0;
        for (int a = 0; a < d; ++a) {
          for (int l = 0; l < L; ++l) {
            const double diff = qi[a * L + l] - qj[a * L + l];
            gamma[l] += diff * diff;
          }
        }
        for (int l = 0; l < L; ++l) gamma[l] -= e.desiredDistanceSquared;
        for (int a = 0; a < d; ++a) {
          for (int l = 0; l < L; ++l) {
            const double term = gamma[l] * (qi[a * L + l] - qj[a * L + l]);
            gi[a * L + l] += term;
            gj[a * L + l] -= term;
          }
        }
      }
      if (k == 1) {
        // Variational start with v_0 = 0 (variationalStart).
        for (int x = 0; x < stride; ++x) {
          qNext[x] = q[x] + c.startGain * (0.0 - 0.5 * c.timeStep * g[x]);
        }
      } else {
        // doc/maths.md §2, explicit update (variationalUpdate).
        for (int x = 0; x < stride; ++x) {
          qNext[x] = c.positionGain * q[x] - c.decay * qPrev[x] - c.gradientGain * g[x];
        }
      }
      std::swap(qPrev, q);
      std::swap(q, qNext);
    }
    // Divergence and congruence at step k, v_k = (q_k - q_{k-1})/h (v_0 = 0).
    bool allDiverged = true;
    for (int l = 0; l < L; ++l) {
      if (diverged[l]) continue;
      for (int x = l; x < stride; x += L) {
        if (!(std::abs(q[x]) <= bound)) {
          diverged[l] = true;
          break;
        }
      }
      allDiverged = allDiverged && diverged[l];
    }
    if (allDiverged) break;
    double ok[L];
    for (int l = 0; l < L; ++l) ok[l] = 1.0;
    for (int i = 0; i < n; ++i) {
      double speed2[L];
      for (int l = 0; l < L; ++l) speed2[l] = 0.0;
      for (int a = 0; a < d; ++a) {
        for (int l = 0; l < L; ++l) {
          const int x = (i * d + a) * L + l;
          const double v = (q[x] - qPrev[x]) / h;
          speed2[l] += v * v;
        }
      }
      for (int l = 0; l < L; ++l) ok[l] = std::sqrt(speed2[l]) < maxSpeed ? ok[l] : 0.0;
    }
    // The O(n^2) pair test only matters for lanes that pass the O(n) speed test.
    bool anySlow = false;
    for (int l = 0; l < L; ++l) anySlow = anySlow || ok[l] != 0.0;
    int pair = 0;
    for (int i = 0; i < n && anySlow; ++i) {
      for (int j = i + 1; j < n; ++j, ++pair) {
        const double desired = desiredPairDistance_[pair];
        double dist2[L];
        for (int l = 0; l < L; ++l) dist2[l] = 0.0;
        for (int a = 0; a < d; ++a) {
          for (int l = 0; l < L; ++l) {
            const double diff = q[(i * d + a) * L + l] - q[(j * d + a) * L + l];
            dist2[l] += diff * diff;
          }
        }
        for (int l = 0; l < L; ++l) {
          ok[l] = std::abs(std::sqrt(dist2[l]) - desired) <= tol * desired ? ok[l] : 0.0;
        }
      }
    }
    for (int l = 0; l < L; ++l) {
      congruent[l] = ok[l] != 0.0;
      if (!congruent[l]) lastIncongruent[l] = k;
    }
  }

  for (int l = 0; l < count; ++l) {
    RoaCell cell = cellAt(first + l);
    cell.diverged = diverged[l];
    cell.converged = !diverged[l] && congruent[l];
    cell.convergedStep = cell.converged ? lastIncongruent[l] + 1 : -1;
    out[l] = cell;
    if (finalPositions) {
      Positions p(d, n);
      for (int i = 0; i < n; ++i)
        for (int a = 0; a < d; ++a) p(a, i) = q[(i * d + a) * L + l];
      finalPositions->push_back(p);
    }
  }
}

std::vector<RoaCell> RoaCampaign::run(int threads, const std::function<void(long)>& progress) const {
  const int cells = cellCount();
  std::vector<RoaCell> results(static_cast<std::size_t>(cells));
  const int batches = (cells + L - 1) / L;
  std::atomic<int> next{0};
  std::atomic<long> done{0};
  const auto worker = [&] {
    for (int b = next++; b < batches; b = next++) {
      const int first = b * L;
      const int count = std::min(L, cells - first);
      simulateBatch(first, count, &results[static_cast<std::size_t>(first)]);
      done += count;
    }
  };
  const int extra = std::max(1, threads) - 1;
  std::vector<std::thread> pool;
  for (int t = 0; t < extra; ++t) pool.emplace_back(worker);
  if (progress) {
    // The calling thread reports progress while the pool works, then joins in.
    std::thread last(worker);
    while (done.load() < cells) {
      progress(done.load());
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    last.join();
    progress(done.load());
  } else {
    worker();
  }
  for (auto& t : pool) t.join();
  return results;
}

}  // namespace vf
