// Region-of-attraction campaigns: thread independence, known cells, scalar = batched, bad flags.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/integrators/integrator.hpp"
#include "variational_formation_core/studies/roa_campaign.hpp"
#include "variational_formation_core/integrators/step_size_advice.hpp"
#include "variational_formation/tools/roa_cli.hpp"

namespace vf {
namespace {

const std::string kHexagon = std::string(VF_SOURCE_DIR) + "/config/hexagon.yaml";

RoaSettings paperSettings() {
  RoaSettings s;
  s.timeStep = 0.014;
  s.dampingGain = 13.0;
  s.steps = 200;
  return s;
}

RoaGrid gridAround(int agent, double half, int n) {
  const Scenario sc = loadScenario(kHexagon);
  RoaGrid g;
  g.agent = agent;
  g.xMin = sc.desiredPositions(0, agent) - half;
  g.xMax = sc.desiredPositions(0, agent) + half;
  g.yMin = sc.desiredPositions(1, agent) - half;
  g.yMax = sc.desiredPositions(1, agent) + half;
  g.nx = g.ny = n;
  return g;
}

bool sameCell(const RoaCell& a, const RoaCell& b) {
  return a.ix == b.ix && a.iy == b.iy && a.x == b.x && a.y == b.y && a.converged == b.converged &&
         a.convergedStep == b.convergedStep && a.diverged == b.diverged;
}

TEST(Roa, SameResultsForOneAndTwoThreads) {
  const RoaCampaign campaign(loadScenario(kHexagon), gridAround(1, 4.0, 13), paperSettings());
  const auto one = campaign.run(1);
  const auto two = campaign.run(2);
  ASSERT_EQ(one.size(), 169u);
  ASSERT_EQ(two.size(), one.size());
  int converged = 0, other = 0;
  for (std::size_t k = 0; k < one.size(); ++k) {
    EXPECT_TRUE(sameCell(one[k], two[k])) << "cell " << k;
    (one[k].converged ? converged : other)++;
  }
  // The grid straddles the region's boundary: both outcomes occur.
  EXPECT_GT(converged, 0);
  EXPECT_GT(other, 0);
}

// The step from which a run stays congruent, measured on any integrator, or -1.
long stepFromWhichCongruent(Integrator& integ, const Formation& f, long steps) {
  long lastIncongruent = -1;
  for (long k = 0; k <= steps; ++k) {
    if (k > 0) integ.step();
    if (!f.isCongruent(integ.positions(), integ.velocities())) lastIncongruent = k;
  }
  return lastIncongruent < steps ? lastIncongruent + 1 : -1;
}

TEST(Roa, KnownConvergingAndDivergingCells) {
  const Scenario sc = loadScenario(kHexagon);
  const Formation f = makeFormation(sc);
  RoaGrid near;
  near.agent = 1;
  near.xMin = near.xMax = sc.desiredPositions(0, 1) + 0.3;
  near.yMin = near.yMax = sc.desiredPositions(1, 1) - 0.2;
  const RoaCell a = RoaCampaign(sc, near, paperSettings()).run(1)[0];
  EXPECT_TRUE(a.converged);
  EXPECT_FALSE(a.diverged);
  // A second method: RK4 at h/10 from the same start reaches congruence at the same time, to
  // within one step h = 0.014 (the VI's backward-difference velocity lags by about h/2; 0.91 s
  // against 0.903 s when this was written).
  Positions q0 = f.desiredShape();
  q0(0, 1) = near.xMin;
  q0(1, 1) = near.yMin;
  const auto rk4 = makeIntegrator(Method::RungeKutta4, f, q0, Positions::Zero(2, 6), 0.0014, 13.0);
  const long rk4Step = stepFromWhichCongruent(*rk4, f, 2000);
  ASSERT_GT(rk4Step, 0);
  EXPECT_NEAR(a.convergedStep * 0.014, rk4Step * 0.0014, 0.014);

  RoaGrid far = near;
  far.xMin = far.xMax = 200.0;
  const RoaCell b = RoaCampaign(sc, far, paperSettings()).run(1)[0];
  EXPECT_TRUE(b.diverged);
  // Why: stiffness ~ 3 |q|^2 there, so h w >> 2 cosh(kappa h / 2) (linearly unstable start).
  Positions qFar = f.desiredShape();
  qFar(0, 1) = 200.0;
  qFar(1, 1) = far.yMin;
  EXPECT_FALSE(isLinearlyStable(0.014, maxStiffnessFrequency(f, qFar), 13.0));
}

TEST(Roa, BatchedPathEqualsScalarPathBitForBit) {
  const RoaCampaign campaign(loadScenario(kHexagon), gridAround(1, 4.0, 7), paperSettings());
  int compared = 0;
  for (int first = 0; first < campaign.cellCount(); first += RoaCampaign::kLanes) {
    const int count = std::min(RoaCampaign::kLanes, campaign.cellCount() - first);
    std::vector<RoaCell> batch(static_cast<std::size_t>(count));
    std::vector<Positions> finals;
    campaign.simulateBatch(first, count, batch.data(), &finals);
    for (int l = 0; l < count; ++l) {
      const RoaCell scalar = campaign.simulateCell(first + l);
      EXPECT_TRUE(sameCell(scalar, batch[static_cast<std::size_t>(l)])) << "cell " << first + l;
      if (!scalar.diverged) {
        const Positions expected = campaign.finalPositionsOfCell(first + l);
        EXPECT_EQ((expected - finals[static_cast<std::size_t>(l)]).cwiseAbs().maxCoeff(), 0.0)
            << "cell " << first + l;
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 40);
}

TEST(Roa, ConvergedStepIsWhereTheRunStaysCongruent) {
  // Rerunning with steps = converged_step - 1 must end incongruent, with steps = converged_step
  // congruent (the definition, checked on the scalar path).
  const Scenario sc = loadScenario(kHexagon);
  RoaGrid g = gridAround(2, 0.0, 1);
  g.xMin = g.xMax = sc.desiredPositions(0, 2) - 0.5;
  RoaSettings s = paperSettings();
  const RoaCell cell = RoaCampaign(sc, g, s).run(1)[0];
  ASSERT_TRUE(cell.converged);
  s.steps = cell.convergedStep;
  EXPECT_TRUE(RoaCampaign(sc, g, s).simulateCell(0).converged);
  s.steps = cell.convergedStep - 1;
  EXPECT_FALSE(RoaCampaign(sc, g, s).simulateCell(0).converged);
}

struct CliResult {
  int status;
  std::string out, err;
};

CliResult roa(std::vector<std::string> args) {
  args.insert(args.begin(), "roa");
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  const int status = runRoaCli(static_cast<int>(argv.size()), argv.data(), out, err, false);
  return {status, out.str(), err.str()};
}

TEST(RoaCli, WritesTheGridAndASummary) {
  const std::string path = ::testing::TempDir() + "vf_roa.csv";
  const CliResult r = roa({"--scenario", kHexagon, "--agent", "1", "--x-range", "-1", "3",
                           "--y-range", "-1", "4", "--resolution", "5", "4", "--steps", "200",
                           "--threads", "2", "--out", path});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("roa: 20 cells"), std::string::npos) << r.out;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "ix,iy,x,y,converged,converged_step,diverged");
  int rows = 0;
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, 20);
}

TEST(RoaCli, DivergedCellsAreAResultNotAnError) {
  // Far from the shape with an overridden, larger h: every cell diverges, exit status 0, and the
  // override's stability warning is printed.
  const std::string path = ::testing::TempDir() + "vf_roa_diverged.csv";
  const CliResult r = roa({"--scenario", kHexagon, "--agent", "1", "--x-range", "200", "201", "--y-range",
                           "0", "0", "--resolution", "2", "1", "--time-step", "0.2", "--kappa", "0",
                           "--steps", "50", "--out", path});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.rfind("roa: warning: --time-step: h = 0.2 exceeds the linear stability limit", 0), 0u) << r.err;
  EXPECT_NE(r.out.find("diverged 100.0%"), std::string::npos) << r.out;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  int rows = 0;
  while (std::getline(in, line)) {
    EXPECT_EQ(line.substr(line.size() - 7), ",0,-1,1") << line;
    ++rows;
  }
  EXPECT_EQ(rows, 2);
}

TEST(RoaCli, BadArgumentsAreOneLineErrorsWithStatusTwo) {
  const std::string out = ::testing::TempDir() + "vf_roa_bad.csv";
  const std::vector<std::string> base{"--scenario", kHexagon, "--x-range", "0", "1", "--y-range", "0",
                                      "1", "--resolution", "3", "3", "--out", out};
  const auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = base;
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases{
      {with({}), "--agent: required"},
      {with({"--agent", "6"}), "--agent: must be between 0 and 5"},
      {with({"--agent", "x"}), "--agent: expected an integer"},
      {with({"--agent", "1", "--threads", "0"}), "--threads: must be between 1"},
      {with({"--agent", "1", "--z", "1"}), "--z: only for 3D"},
      {with({"--agent", "1", "--tolerance", "-1"}), "--tolerance: must be > 0"},
      {with({"--agent", "1", "--kappa", "-1"}), "--kappa: must be finite and >= 0, got -1"},
      // Overrides go through the scenario's validation: the limits of README "Limits".
      {with({"--agent", "1", "--kappa", "1e200"}), "--kappa * time_step: must be <= 708.3964185322641"},
      {with({"--agent", "1", "--time-step", "1e200"}), "--time-step: must be <= 9.480751908109176e+153 s"},
      {with({"--agent", "1", "--time-step", "0"}), "--time-step: must be finite and > 0, got 0"},
      {with({"--agent", "1", "--time-step", "1e-170"}), "--time-step: too small"},
      {with({"--agent", "1", "--steps", "0"}), "--steps: must be >= 1 here, got 0"},
      {with({"--agent", "1", "--frobnicate"}), "--frobnicate: unknown flag"},
      {{"--scenario", "/nonexistent.yaml", "--agent", "0", "--x-range", "0", "1", "--y-range", "0", "1",
        "--resolution", "2", "2", "--out", out},
       "cannot open the scenario file"},
      {{"--scenario", kHexagon, "--agent", "0", "--x-range", "2", "1", "--y-range", "0", "1",
        "--resolution", "2", "2", "--out", out},
       "--x-range: A must be <= B"},
      {{"--scenario", kHexagon, "--agent", "0", "--x-range", "0", "1", "--y-range", "0", "1",
        "--resolution", "0", "2", "--out", out},
       "--resolution: must be between 1"},
      {{"--scenario", kHexagon, "--agent", "0", "--x-range", "0", "1", "--y-range", "0", "1",
        "--resolution", "2", "2", "--out", "/nonexistent/dir/roa.csv"},
       "--out: cannot write"},
  };
  for (const auto& [args, fragment] : cases) {
    const CliResult r = roa(args);
    EXPECT_EQ(r.status, 2) << fragment;
    EXPECT_EQ(r.err.rfind("roa: error: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err << " / " << fragment;
  }
}

}  // namespace
}  // namespace vf
