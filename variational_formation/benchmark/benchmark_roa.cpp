// Region-of-attraction throughput (simulations per second): the batched campaign against a
// plain one-simulation-at-a-time loop, explicit Euler and RK4 at the same step, and scaling
// with the number of agents and edges. Run with scripts/benchmark_roa.sh.
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>
#include <thread>

#include "variational_formation_core/integrators/integrator.hpp"
#include "variational_formation_core/studies/roa_campaign.hpp"

namespace {

using vf::RoaCampaign;

const std::string kHexagon = std::string(VF_SOURCE_DIR) + "/config/hexagon.yaml";

vf::RoaSettings paperSettings() {
  vf::RoaSettings s;
  s.timeStep = 0.014;
  s.dampingGain = 13.0;
  s.steps = 200;
  return s;
}

// The paper's campaign: a 55 x 55 grid (3025 simulations) around agent 1 of the hexagon.
vf::RoaGrid paperGrid(int n) {
  vf::RoaGrid g;
  g.agent = 1;
  g.xMin = -1.0;
  g.xMax = 4.0;
  g.yMin = 0.0;
  g.yMax = 5.0;
  g.nx = g.ny = n;
  return g;
}

void setRate(benchmark::State& state, double simulations) {
  state.counters["sims_per_s"] =
      benchmark::Counter(simulations, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_HexagonCampaign(benchmark::State& state) {
  const RoaCampaign campaign(vf::loadScenario(kHexagon), paperGrid(55), paperSettings());
  const int threads = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(campaign.run(threads));
  setRate(state, campaign.cellCount());
}
BENCHMARK(BM_HexagonCampaign)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_PlainLoop(benchmark::State& state) {
  const RoaCampaign campaign(vf::loadScenario(kHexagon), paperGrid(55), paperSettings());
  const int cells = 64;
  for (auto _ : state) {
    for (int c = 0; c < cells; ++c) benchmark::DoNotOptimize(campaign.simulateCell(c * 47));
  }
  setRate(state, cells);
}
BENCHMARK(BM_PlainLoop)->Unit(benchmark::kMillisecond);

// One simulation at a time with another method, and the same per-step congruence test.
void runMethod(benchmark::State& state, vf::Method method) {
  const vf::Scenario sc = vf::loadScenario(kHexagon);
  const vf::Formation f = vf::makeFormation(sc);
  vf::Positions q0 = f.desiredShape();
  q0(0, 1) += 0.7;
  const int cells = 64;
  for (auto _ : state) {
    for (int c = 0; c < cells; ++c) {
      auto integ = vf::makeIntegrator(method, f, q0, vf::Positions::Zero(2, 6), 0.014, 13.0);
      bool congruent = false;
      for (int k = 0; k < 200; ++k) {
        integ->step();
        congruent = f.isCongruent(integ->positions(), integ->velocities());
      }
      benchmark::DoNotOptimize(congruent);
    }
  }
  setRate(state, cells);
}
void BM_PlainLoopVariational(benchmark::State& s) { runMethod(s, vf::Method::Variational); }
void BM_PlainLoopEuler(benchmark::State& s) { runMethod(s, vf::Method::ExplicitEuler); }
void BM_PlainLoopRK4(benchmark::State& s) { runMethod(s, vf::Method::RungeKutta4); }
BENCHMARK(BM_PlainLoopVariational)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PlainLoopEuler)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PlainLoopRK4)->Unit(benchmark::kMillisecond);

// n agents on a circle of radius n/2, each joined to its next `span` neighbours (span n edges).
vf::Scenario ring(int n, int span) {
  vf::Scenario s;
  s.name = "ring";
  s.dimension = 2;
  s.dampingGain = 13.0;
  s.timeStep = 0.014;
  s.steps = 200;
  s.desiredPositions.resize(2, n);
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    s.desiredPositions.col(i) << 0.5 * n * std::cos(a), 0.5 * n * std::sin(a);
  }
  s.initialPositions = s.desiredPositions;
  s.initialVelocities = vf::Positions::Zero(2, n);
  for (int i = 0; i < n; ++i)
    for (int k = 1; k <= span; ++k) s.edges.emplace_back(i, (i + k) % n);
  return s;
}

void BM_ScalingAgents(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int span = static_cast<int>(state.range(1));
  const vf::Scenario s = ring(n, span);
  vf::RoaGrid g;
  g.agent = 0;
  g.xMin = s.desiredPositions(0, 0) - 0.5;
  g.xMax = s.desiredPositions(0, 0) + 0.5;
  g.yMin = g.yMax = 0.2;
  g.nx = 64;
  const RoaCampaign campaign(s, g, paperSettings());
  const int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (auto _ : state) benchmark::DoNotOptimize(campaign.run(threads));
  setRate(state, campaign.cellCount());
  state.counters["edges"] = static_cast<double>(s.edges.size());
}
BENCHMARK(BM_ScalingAgents)
    ->Args({6, 2})->Args({20, 2})->Args({50, 2})->Args({100, 2})
    ->Args({20, 4})->Args({20, 8})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
