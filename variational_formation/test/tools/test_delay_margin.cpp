// The delayed model's flags on simulate and the delay_margin CLI: outputs and one-line errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "variational_formation/tools/delay_margin_cli.hpp"
#include "variational_formation/tools/simulate_cli.hpp"

namespace vf {
namespace {

const std::string kConfig = std::string(VF_SOURCE_DIR) + "/config/";

struct CliResult {
  int status;
  std::string out;
  std::string err;
};

CliResult call(bool simulate, std::vector<std::string> args) {
  args.insert(args.begin(), simulate ? "simulate" : "delay_margin");
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  const int argc = static_cast<int>(argv.size());
  const int status = simulate ? runSimulateCli(argc, argv.data(), out, err)
                              : runDelayMarginCli(argc, argv.data(), out, err, false);
  return {status, out.str(), err.str()};
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void expectBadInput(bool simulate, const std::vector<std::string>& args, const std::string& fragment) {
  const CliResult r = call(simulate, args);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err << " / " << fragment;
}

TEST(DelayFlags, ZeroDelayAndZeroLossWriteTheOrdinaryFiles) {
  const std::string dir = ::testing::TempDir();
  const std::vector<std::string> base = {"--scenario", kConfig + "hexagon.yaml", "--steps", "50"};
  auto with = [&](const std::string& name, std::vector<std::string> extra) {
    std::vector<std::string> a = base;
    a.insert(a.end(), {"--out", dir + name + ".csv", "--metrics", dir + name + "_m.csv"});
    a.insert(a.end(), extra.begin(), extra.end());
    EXPECT_EQ(call(true, a).status, 0);
    return slurp(dir + name + ".csv") + slurp(dir + name + "_m.csv");
  };
  const std::string plain = with("vf_plain", {});
  EXPECT_EQ(with("vf_d0", {"--delay-steps", "0"}), plain);
  EXPECT_EQ(with("vf_d0p0", {"--delay-steps", "0", "--loss", "0", "--seed", "4"}), plain);
  EXPECT_NE(with("vf_d2", {"--delay-steps", "2"}), plain);
  const std::string lossy = with("vf_p", {"--loss", "0.3", "--seed", "4"});
  EXPECT_NE(lossy, plain);
  EXPECT_EQ(with("vf_p2", {"--loss", "0.3", "--seed", "4"}), lossy);
}

TEST(DelayFlags, BadValuesAreOneLine) {
  const std::vector<std::string> base = {"--scenario", kConfig + "hexagon.yaml", "--out",
                                         ::testing::TempDir() + "vf_bad.csv"};
  const auto bad = [&](std::vector<std::string> extra, const std::string& fragment) {
    std::vector<std::string> a = base;
    a.insert(a.end(), extra.begin(), extra.end());
    expectBadInput(true, a, fragment);
  };
  bad({"--delay-steps", "-1"}, "--delay-steps");
  bad({"--delay-steps", "2.5"}, "--delay-steps: expected an integer");
  bad({"--loss", "1.5"}, "--loss: must be a probability in [0, 1], got 1.5\n");  // as given, not 1.500000
  bad({"--loss", "-0.1"}, "--loss");
  bad({"--loss", "0.1", "--method", "euler"}, "only with --method vi");
  bad({"--delay-steps", "1", "--method", "rk4"}, "only with --method vi");
  bad({"--seed", "3"}, "--seed: only with --loss");
}

TEST(DelayMarginCli, PrintsBothMarginsAndWritesTheCsvs) {
  const std::string dir = ::testing::TempDir();
  const CliResult r = call(false, {"--scenario", kConfig + "hexagon.yaml", "--kappa", "4",
                                   "--out-dir", dir, "--runs", "4", "--steps", "3000",
                                   "--losses", "0,0.5", "--threads", "2"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("predicted margin D* = 3 steps"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("simulated margin = 3 steps"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("wall time"), std::string::npos);
  const std::string summary = slurp(dir + "/hexagon_delay_margin.csv");
  EXPECT_EQ(summary.rfind("delay_steps,loss,runs,congruent_fraction", 0), 0u);
  EXPECT_EQ(std::count(summary.begin(), summary.end(), '\n'), 1 + 7 * 2);  // D = 0..6
  EXPECT_EQ(slurp(dir + "/hexagon_D4_P0.5.csv").rfind("run,congruent,congruent_step", 0), 0u);
}

TEST(DelayMarginCli, CreatesTheOutputDirectoryWithItsParents) {
  const std::string dir = ::testing::TempDir() + "vf_dm_new/a/b";
  std::remove((dir + "/hexagon_delay_margin.csv").c_str());
  const CliResult r = call(false, {"--scenario", kConfig + "hexagon.yaml", "--kappa", "4",
                                   "--out-dir", dir, "--runs", "1", "--steps", "200",
                                   "--losses", "0", "--delays", "0", "0", "--threads", "1"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(dir + "/hexagon_delay_margin.csv").rfind("delay_steps,loss", 0), 0u);
  // A directory below a regular file cannot be made: one line, status 2.
  const std::string file = ::testing::TempDir() + "vf_dm_file";
  std::ofstream(file) << "x\n";
  expectBadInput(false, {"--scenario", kConfig + "hexagon.yaml", "--out-dir", file + "/sub"},
                 "--out-dir: cannot create the directory '" + file + "/sub'");
}

TEST(DelayMarginCli, NoNeighboursIsSaid) {
  const CliResult r = call(false, {"--scenario", kConfig + "free_particle.yaml", "--out-dir",
                                   ::testing::TempDir()});
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("no edges"), std::string::npos) << r.out;
}

TEST(DelayMarginCli, BadFlagsAreOneLine) {
  const std::vector<std::string> base = {"--scenario", kConfig + "hexagon.yaml", "--out-dir",
                                         ::testing::TempDir()};
  const auto bad = [&](std::vector<std::string> extra, const std::string& fragment) {
    std::vector<std::string> a = base;
    a.insert(a.end(), extra.begin(), extra.end());
    expectBadInput(false, a, fragment);
  };
  bad({"--losses", "0,2"}, "--losses");
  bad({"--delays", "5", "2"}, "--delays: A must be <= B");
  bad({"--delays", "-1", "2"}, "--delays");
  bad({"--runs", "0"}, "--runs");
  bad({"--kappa", "-1"}, "--kappa");
  expectBadInput(false, {"--scenario", kConfig + "hexagon.yaml"}, "--out-dir: required");
}

}  // namespace
}  // namespace vf
