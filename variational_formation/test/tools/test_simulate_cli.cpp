// The simulate CLI: formats (checked against the library's own run, number for number),
// overrides, one-line errors with exit status 2, and exit status 1 when the run diverges.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/integrators/step_metrics.hpp"
#include "variational_formation_core/model/validation.hpp"
#include "variational_formation/tools/arguments.hpp"
#include "variational_formation/tools/simulate_cli.hpp"
#include "simulate_test_support.hpp"

namespace vf {
namespace {

using namespace test;  // NOLINT: the shared simulate helpers (simulate_test_support.hpp)

std::vector<std::string> lines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> result;
  for (std::string line; std::getline(in, line);) result.push_back(line);
  return result;
}

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "vf_cli_" + name;
}

// The comma-separated fields of a CSV row, parsed as doubles (strtod reads "nan" and "inf").
std::vector<double> numbers(const std::string& row) {
  std::vector<double> values;
  const char* p = row.c_str();
  for (;;) {
    char* end = nullptr;
    values.push_back(std::strtod(p, &end));
    EXPECT_NE(end, p) << row;
    if (*end != ',') break;
    p = end + 1;
  }
  return values;
}

TEST(SimulateCli, WritesTrajectoryAndMetricsThatRoundTripTheLibrarysRun) {
  const std::string traj = tempPath("traj.csv"), metrics = tempPath("metrics.csv");
  const CliResult r = simulate({"--scenario", kConfig + "square.yaml", "--out", traj, "--metrics", metrics,
                                "--steps", "20"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto t = lines(traj);
  const auto m = lines(metrics);
  ASSERT_EQ(t.size(), 1u + 21u * 4u);
  ASSERT_EQ(m.size(), 22u);
  EXPECT_EQ(t[0], "step,t,agent,x,y,z");
  EXPECT_EQ(m[0], "step,t,energy,max_distance_error,px,py,pz,ax,ay,az,cvx,cvy,cvz,wx,wy,wz,scale_error,shape_error");

  // The same run through the library: every written number must read back as the very double
  // the library computed (17 significant digits round-trip), z = 0 in 2D.
  Scenario scenario = loadScenario(kConfig + "square.yaml");
  scenario.steps = 20;
  std::size_t row = 1;
  runScenario(scenario, Method::Variational, StartMethod::Variational, [&](const Integrator& integ) {
    const StepMetrics expected = measure(integ);
    const std::vector<double> mv = numbers(m[static_cast<std::size_t>(integ.stepIndex()) + 1]);
    ASSERT_EQ(mv.size(), 18u);
    const double metricValues[] = {static_cast<double>(expected.step), expected.time, expected.energy,
                                   expected.maxDistanceError,         expected.linearMomentum(0),
                                   expected.linearMomentum(1),        expected.linearMomentum(2),
                                   expected.angularMomentum(0),       expected.angularMomentum(1),
                                   expected.angularMomentum(2),       expected.centroidVelocity(0),
                                   expected.centroidVelocity(1),      expected.centroidVelocity(2),
                                   expected.rotationRate(0),          expected.rotationRate(1),
                                   expected.rotationRate(2),          expected.scaleError,
                                   expected.shapeError};
    for (int c = 0; c < 18; ++c) EXPECT_EQ(mv[c], metricValues[c]) << "metrics step " << expected.step << " column " << c;
    for (int i = 0; i < 4; ++i, ++row) {
      const std::vector<double> tv = numbers(t[row]);
      ASSERT_EQ(tv.size(), 6u);
      EXPECT_EQ(tv[0], static_cast<double>(integ.stepIndex()));
      EXPECT_EQ(tv[1], integ.time());
      EXPECT_EQ(tv[2], i);
      EXPECT_EQ(tv[3], integ.positions()(0, i)) << t[row];
      EXPECT_EQ(tv[4], integ.positions()(1, i)) << t[row];
      EXPECT_EQ(tv[5], 0.0);
    }
  });
  EXPECT_EQ(row, t.size());
  // Independent of the library: t = k h with h = 0.005 from the file.
  EXPECT_DOUBLE_EQ(numbers(t.back())[1], 20 * 0.005);
}

TEST(SimulateCli, DivergedRunExitsOneNamingTheFirstNonFiniteStep) {
  // h = 0.5 is above the stability limit (0.32 s at kappa = 0): warned, then the run blows up.
  const std::string traj = tempPath("diverged.csv");
  const CliResult r = simulate({"--scenario", kConfig + "square.yaml", "--out", traj, "--steps", "40",
                                "--time-step", "0.5", "--kappa", "0"});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(r.err.rfind("simulate: warning: --time-step: h = 0.5 exceeds the linear stability limit", 0), 0u)
      << r.err;
  // The first non-finite step, read from the trajectory itself.
  long firstNonFinite = -1;
  const auto t = lines(traj);
  for (std::size_t k = 1; k < t.size() && firstNonFinite < 0; ++k) {
    const std::vector<double> v = numbers(t[k]);
    if (!(std::isfinite(v[3]) && std::isfinite(v[4]))) firstNonFinite = static_cast<long>(v[0]);
  }
  ASSERT_GT(firstNonFinite, 0);
  const std::string error = "simulate: error: the run diverged: non-finite positions from step " +
                            std::to_string(firstNonFinite) + " (try a smaller --time-step)\n";
  ASSERT_GE(r.err.size(), error.size());
  EXPECT_EQ(r.err.substr(r.err.size() - error.size()), error);  // the last line, the only error
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;
}

TEST(SimulateCli, OverridesChangeTheRun) {
  const std::string a = tempPath("a.csv"), b = tempPath("b.csv");
  ASSERT_EQ(simulate({"--scenario", kConfig + "hexagon.yaml", "--out", a, "--steps", "5"}).status, 0);
  ASSERT_EQ(simulate({"--scenario", kConfig + "hexagon.yaml", "--out", b, "--steps", "5",
                      "--time-step", "0.001", "--kappa", "0", "--method", "rk4"}).status, 0);
  const auto la = lines(a), lb = lines(b);
  ASSERT_EQ(la.size(), 1u + 6u * 6u);
  ASSERT_EQ(lb.size(), la.size());
  EXPECT_NE(la.back(), lb.back());
  double step, time;
  ASSERT_EQ(std::sscanf(lb.back().c_str(), "%lf,%lf", &step, &time), 2);
  EXPECT_EQ(step, 5.0);
  EXPECT_DOUBLE_EQ(time, 5 * 0.001);
}

TEST(SimulateCli, InitOnlyAppliesToTheVariationalMethod) {
  for (const char* init : {"variational", "paper"}) {
    const CliResult r = simulate({"--scenario", kConfig + "tetrahedron.yaml", "--out", tempPath("m.csv"),
                                  "--steps", "3", "--method", "vi", "--init", init});
    EXPECT_EQ(r.status, 0) << init << ": " << r.err;
  }
  for (const char* method : {"euler", "rk4"}) {
    const CliResult r = simulate({"--scenario", kConfig + "tetrahedron.yaml", "--out", tempPath("m.csv"),
                                  "--steps", "3", "--method", method});
    EXPECT_EQ(r.status, 0) << method << ": " << r.err;
    for (const char* init : {"variational", "paper"}) {
      expectBadInput({"--scenario", kConfig + "tetrahedron.yaml", "--out", tempPath("m.csv"), "--steps", "3",
                      "--method", method, "--init", init},
                     std::string("--init: only for --method vi (euler and rk4 start from v_0 directly), got --method ") +
                         method);
    }
  }
}

// README's `simulate --scenario deploy6.yaml`: only how the run ended, the same lines as with
// --out, and no file; --metrics alone still writes its file, the same as beside --out.
TEST(SimulateCli, WithoutOutItSaysHowTheRunEndedAndWritesNoTrajectory) {
  const std::string traj = tempPath("kept_traj.csv"), a = tempPath("metrics_a.csv"), b = tempPath("metrics_b.csv");
  std::remove(traj.c_str());
  const CliResult with = simulate({"--scenario", kConfig + "square.yaml", "--steps", "30", "--out", traj,
                                   "--metrics", a});
  ASSERT_EQ(with.status, 0) << with.err;
  std::remove(traj.c_str());
  const CliResult without = simulate({"--scenario", kConfig + "square.yaml", "--steps", "30", "--metrics", b});
  ASSERT_EQ(without.status, 0) << without.err;
  EXPECT_EQ(without.out, with.out);
  EXPECT_EQ(without.out.rfind("formation: ", without.out.rfind('\n', without.out.size() - 2) + 1),
            without.out.rfind('\n', without.out.size() - 2) + 1)
      << without.out;
  EXPECT_EQ(lines(b), lines(a));
  EXPECT_EQ(lines(b).size(), 32u);
  EXPECT_FALSE(std::ifstream(traj).good());
  const CliResult bare = simulate({"--scenario", kConfig + "square.yaml", "--steps", "30"});
  EXPECT_EQ(bare.status, 0) << bare.err;
  EXPECT_EQ(bare.out, with.out);
  EXPECT_EQ(bare.err, "");
}

TEST(SimulateCli, HelpExitsZero) {
  const CliResult r = simulate({"--help"});
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("--scenario"), std::string::npos);
}

TEST(SimulateCli, BadFlagsAreOneLineErrorsWithStatusTwo) {
  const std::string sc = kConfig + "square.yaml", out = tempPath("x.csv");
  expectBadInput({"--scenario", sc, "--out", out, "--bogus"}, "--bogus: unknown flag");
  expectBadInput({"--scenario", sc, "--out"}, "--out: expects 1 value");
  expectBadInput({"--out", out}, "--scenario: required");
  expectBadInput({"--scenario", sc, "--out", out, "--time-step", "abc"}, "--time-step: expected a finite number");
  expectBadInput({"--scenario", sc, "--out", out, "--time-step", "0"}, "--time-step: must be finite and > 0, got 0");
  expectBadInput({"--scenario", sc, "--out", out, "--time-step", "-1"}, "--time-step: must be finite and > 0, got -1");
  expectBadInput({"--scenario", sc, "--out", out, "--time-step", "nan"}, "--time-step: expected a finite number");
  expectBadInput({"--scenario", sc, "--out", out, "--steps", "0"}, "--steps: must be >= 1 here, got 0");
  expectBadInput({"--scenario", sc, "--out", out, "--steps", "1e3"}, "--steps: expected an integer");
  expectBadInput({"--scenario", sc, "--out", out, "--kappa", "-1"}, "--kappa: must be finite and >= 0, got -1");
  expectBadInput({"--scenario", sc, "--out", out, "--method", "verlet"}, "--method: unknown method 'verlet'");
  expectBadInput({"--scenario", sc, "--out", out, "--init", "zero"}, "--init: unknown start 'zero'");
  expectBadInput({"--scenario", sc, "--out", "/nonexistent/dir/x.csv"}, "--out: cannot write");
  expectBadInput({"--scenario", sc, "--out", out, "--metrics", "/nonexistent/m.csv"}, "--metrics: cannot write");
  expectBadInput({"--scenario", "/nonexistent.yaml", "--out", out}, "cannot open the scenario file");
  expectBadInput({"--scenario", sc, "--out", out, "--steps", "3", "--steps", "4"}, "--steps: given more than once");
}

TEST(SimulateCli, OverridesBeyondTheLimitsAreOneLineErrors) {
  const std::string sc = kConfig + "square.yaml", out = tempPath("x.csv");
  expectBadInput({"--scenario", sc, "--out", out, "--time-step", "1e200"},
                 "--time-step: must be <= 9.480751908109176e+153 s (beyond it 2 h^2 overflows), got 1e+200");
  expectBadInput({"--scenario", sc, "--out", out, "--kappa", "1e200"},
                 "--kappa * time_step: must be <= 708.3964185322641");
  expectBadInput({"--scenario", sc, "--out", out, "--kappa", "1e200", "--time-step", "0.1"},
                 "--kappa * --time-step: must be <= 708.3964185322641");
  expectBadInput({"--scenario", sc, "--out", out, "--time-step", "1e-170"}, "--time-step: too small, the gain");
  expectBadInput({"--scenario", sc, "--out", out, "--steps", "9007199254740993"},
                 "--steps: must be between 0 and 9007199254740992");
  // At the limit kappa h = 708.3964185322641 (h = 1): accepted, and it runs.
  const CliResult r = simulate({"--scenario", sc, "--out", out, "--time-step", "1", "--kappa",
                                "708.3964185322641", "--steps", "1"});
  EXPECT_EQ(r.status, 0) << r.err;
}

// Writes config/square.yaml with `from` replaced by `to` and returns its path.
std::string modifiedSquare(const std::string& name, const std::string& from, const std::string& to) {
  std::ifstream in(kConfig + "square.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  s.replace(s.find(from), from.size(), to);
  const std::string path = tempPath(name);
  std::ofstream(path) << s;
  return path;
}

TEST(SimulateCli, BadScenarioNamesTheField) {
  expectBadInput({"--scenario", modifiedSquare("bad.yaml", "[0, 2]", "[0, 9]"), "--out", tempPath("x.csv")},
                 "edges[4]: agent 9 does not exist");
}

TEST(SimulateCli, UnboundedScenarioIsRejected) {
  expectBadInput({"--scenario", modifiedSquare("unbounded.yaml", "steps: 1200", "steps: 0"), "--out",
                  tempPath("x.csv")},
                 "steps: must be >= 1 here, got 0");
}

TEST(Arguments, IntegerRangeAndValues) {
  const char* argv[] = {"tool", "--n", "5", "--r", "1", "2"};
  const Arguments args(6, argv, {{"--n", 1}, {"--r", 2}});
  EXPECT_EQ(args.integer("--n", 0, 10), 5);
  EXPECT_THROW(args.integer("--n", 6, 10), InvalidInput);
  EXPECT_DOUBLE_EQ(args.number("--r", 1), 2.0);
  EXPECT_FALSE(args.has("--x"));
  EXPECT_THROW(args.text("--x"), InvalidInput);
}

}  // namespace
}  // namespace vf
