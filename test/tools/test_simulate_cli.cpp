// The simulate CLI (doc/architecture.md, file formats): formats, overrides, and one-line errors with exit status 2.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "variational_formation/core/error.hpp"
#include "variational_formation/tools/arguments.hpp"
#include "variational_formation/tools/simulate_cli.hpp"

namespace vf {
namespace {

const std::string kConfig = std::string(VF_SOURCE_DIR) + "/config/";

struct CliResult {
  int status;
  std::string out;
  std::string err;
};

CliResult simulate(std::vector<std::string> args) {
  args.insert(args.begin(), "simulate");
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  const int status = runSimulateCli(static_cast<int>(argv.size()), argv.data(), out, err);
  return {status, out.str(), err.str()};
}

std::vector<std::string> lines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> result;
  for (std::string line; std::getline(in, line);) result.push_back(line);
  return result;
}

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "vf_cli_" + name;
}

void expectBadInput(const std::vector<std::string>& args, const std::string& fragment) {
  const CliResult r = simulate(args);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("simulate: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err << " / " << fragment;
}

TEST(SimulateCli, WritesTrajectoryAndMetrics) {
  const std::string traj = tempPath("traj.csv"), metrics = tempPath("metrics.csv");
  const CliResult r = simulate({"--scenario", kConfig + "square.yaml", "--out", traj, "--metrics", metrics,
                          "--steps", "20"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto t = lines(traj);
  ASSERT_EQ(t.size(), 1u + 21u * 4u);
  EXPECT_EQ(t[0], "step,t,agent,x,y,z");
  EXPECT_EQ(t[1].substr(0, 6), "0,0,0,");
  EXPECT_EQ(t.back().substr(0, 3), "20,");
  // 2D: z = 0; 17 significant digits round-trip the doubles.
  EXPECT_EQ(t[5].substr(t[5].rfind(',')), ",0");
  double step, time, agent, x;
  ASSERT_EQ(std::sscanf(t.back().c_str(), "%lf,%lf,%lf,%lf", &step, &time, &agent, &x), 4);
  EXPECT_DOUBLE_EQ(time, 20 * 0.005);
  const auto m = lines(metrics);
  ASSERT_EQ(m.size(), 22u);
  EXPECT_EQ(m[0], "step,t,energy,max_distance_error,px,py,pz,ax,ay,az");
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

TEST(SimulateCli, MethodsAndStartsAllRun) {
  for (const char* method : {"vi", "euler", "rk4"}) {
    for (const char* init : {"variational", "paper"}) {
      const CliResult r = simulate({"--scenario", kConfig + "tetrahedron.yaml", "--out", tempPath("m.csv"),
                              "--steps", "3", "--method", method, "--init", init});
      EXPECT_EQ(r.status, 0) << method << " " << init << ": " << r.err;
    }
  }
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
  expectBadInput({"--scenario", sc}, "--out: required");
  expectBadInput({"--out", out}, "--scenario: required");
  expectBadInput({"--scenario", sc, "--out", out, "--time-step", "abc"}, "--time-step: expected a finite number");
  expectBadInput({"--scenario", sc, "--out", out, "--time-step", "0"}, "--time-step: must be > 0");
  expectBadInput({"--scenario", sc, "--out", out, "--time-step", "-1"}, "--time-step: must be > 0");
  expectBadInput({"--scenario", sc, "--out", out, "--time-step", "nan"}, "--time-step: expected a finite number");
  expectBadInput({"--scenario", sc, "--out", out, "--steps", "0"}, "--steps: must be between 1");
  expectBadInput({"--scenario", sc, "--out", out, "--steps", "1e3"}, "--steps: expected an integer");
  expectBadInput({"--scenario", sc, "--out", out, "--kappa", "-1"}, "--kappa: must be >= 0");
  expectBadInput({"--scenario", sc, "--out", out, "--method", "verlet"}, "--method: unknown method 'verlet'");
  expectBadInput({"--scenario", sc, "--out", out, "--init", "zero"}, "--init: unknown start 'zero'");
  expectBadInput({"--scenario", sc, "--out", "/nonexistent/dir/x.csv"}, "--out: cannot write");
  expectBadInput({"--scenario", sc, "--out", out, "--metrics", "/nonexistent/m.csv"}, "--metrics: cannot write");
  expectBadInput({"--scenario", "/nonexistent.yaml", "--out", out}, "cannot open the scenario file");
  expectBadInput({"--scenario", sc, "--out", out, "--steps", "3", "--steps", "4"}, "--steps: given more than once");
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
                 "steps: must be >= 1");
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
