// One step of the centralised integrators on a 1000-agent ring with chords (each agent joined to
// its next two), no output: the cost of the force model and the update alone, without the CSV
// writing that dominates `simulate`. Plain, under a turning and scaling command, and with
// neighbour states two steps old. Run: .ws/devel/lib/variational_formation/benchmark_integrators.
#include <benchmark/benchmark.h>

#include <cmath>

#include "variational_formation_core/integrators/delayed_variational_integrator.hpp"
#include "variational_formation_core/manoeuvres/manoeuvre_integrator.hpp"
#include "variational_formation_core/integrators/variational_integrator.hpp"

namespace {

struct Ring {
  Ring() : formation(2, shape(), edges()), q0(formation.desiredShape()), v0(vf::Positions::Zero(2, kAgents)) {
    // The same small, fixed disturbance for every run: agent i moved by 0.05 m along a direction
    // turning with i.
    for (int i = 0; i < kAgents; ++i) {
      q0(0, i) += 0.05 * std::cos(0.37 * i);
      q0(1, i) += 0.05 * std::sin(0.37 * i);
    }
  }
  static constexpr int kAgents = 1000;
  static vf::Positions shape() {
    vf::Positions p(2, kAgents);
    for (int i = 0; i < kAgents; ++i) {
      const double a = 2.0 * M_PI * i / kAgents;
      p.col(i) << 0.5 * kAgents / M_PI * std::cos(a), 0.5 * kAgents / M_PI * std::sin(a);  // 1 m apart
    }
    return p;
  }
  static std::vector<std::pair<int, int>> edges() {
    std::vector<std::pair<int, int>> e;
    for (int i = 0; i < kAgents; ++i) {
      e.emplace_back(i, (i + 1) % kAgents);
      e.emplace_back(i, (i + 2) % kAgents);
    }
    return e;
  }
  vf::Formation formation;
  vf::Positions q0, v0;
};

constexpr double kTimeStep = 0.005, kDampingGain = 2.0;

void stepRate(benchmark::State& state) {
  state.counters["steps_per_s"] = benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_RingVariational(benchmark::State& state) {
  const Ring ring;
  vf::VariationalIntegrator vi(ring.formation, ring.q0, ring.v0, kTimeStep, kDampingGain, vf::StartMethod::Variational);
  for (auto _ : state) {
    vi.step();
    benchmark::DoNotOptimize(vi.positions().data());
  }
  stepRate(state);
}
BENCHMARK(BM_RingVariational)->Unit(benchmark::kMicrosecond);

void BM_RingManoeuvre(benchmark::State& state) {
  const Ring ring;
  vf::Command turn;
  turn.velocity.x() = 0.2;
  turn.angularRate.z() = 0.01;
  turn.scale = 1.1;
  vf::CommandSchedule schedule;
  schedule.add(0, turn);
  vf::ManoeuvreIntegrator mi(ring.formation, ring.q0, ring.v0, kTimeStep, kDampingGain, vf::StartMethod::Variational,
                             schedule);
  for (auto _ : state) {
    mi.step();
    benchmark::DoNotOptimize(mi.positions().data());
  }
  stepRate(state);
}
BENCHMARK(BM_RingManoeuvre)->Unit(benchmark::kMicrosecond);

void BM_RingDelayed(benchmark::State& state) {
  const Ring ring;
  vf::DelaySettings delay;
  delay.delaySteps = 2;
  vf::DelayedVariationalIntegrator di(ring.formation, ring.q0, ring.v0, kTimeStep, kDampingGain,
                                      vf::StartMethod::Variational, delay);
  for (auto _ : state) {
    di.step();
    benchmark::DoNotOptimize(di.positions().data());
  }
  stepRate(state);
}
BENCHMARK(BM_RingDelayed)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
