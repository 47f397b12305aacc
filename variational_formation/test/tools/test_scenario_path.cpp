// Scenario names in the tools (tools/scenario_path.hpp): a bare name is <name>.yaml in the
// package's config/ (ROS_PACKAGE_PATH first, then the compiled-in folders), a path that exists
// always wins, and an unknown name is one error listing where it was looked for.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation/tools/scenario_path.hpp"
#include "variational_formation/tools/simulate_cli.hpp"

namespace vf {
namespace {

namespace fs = std::filesystem;
const std::string kSourceConfig = std::string(VF_SOURCE_DIR) + "/config";

/// A scratch folder, ROS_PACKAGE_PATH and the working directory set for one test, restored after.
class ScenarioPathTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* old = std::getenv("ROS_PACKAGE_PATH");
    hadPath_ = old != nullptr;
    if (hadPath_) oldPath_ = old;
    unsetenv("ROS_PACKAGE_PATH");
    oldCwd_ = fs::current_path();
    dir_ = fs::temp_directory_path() / ("vf_scenario_path_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    fs::current_path(dir_);
  }
  void TearDown() override {
    fs::current_path(oldCwd_);
    fs::remove_all(dir_);
    if (hadPath_) setenv("ROS_PACKAGE_PATH", oldPath_.c_str(), 1);
    else unsetenv("ROS_PACKAGE_PATH");
  }
  static void write(const fs::path& path, const std::string& text) {
    fs::create_directories(path.parent_path());
    std::ofstream(path) << text;
  }
  fs::path dir_;

 private:
  bool hadPath_ = false;
  std::string oldPath_;
  fs::path oldCwd_;
};

TEST_F(ScenarioPathTest, BareNameIsFoundInTheSourceConfigWithoutRos) {
  EXPECT_EQ(resolveScenario("hexagon"), kSourceConfig + "/hexagon.yaml");
  EXPECT_EQ(resolveScenario("hexagon.yaml"), kSourceConfig + "/hexagon.yaml");
}

TEST_F(ScenarioPathTest, RosPackagePathComesFirst) {
  write(dir_ / "ws/src/variational_formation/config/hexagon.yaml", "x");
  setenv("ROS_PACKAGE_PATH", (dir_ / "ws/src").c_str(), 1);
  EXPECT_EQ(resolveScenario("hexagon"), (dir_ / "ws/src/variational_formation/config/hexagon.yaml").string());
  // An entry that is the package itself, with a trailing slash; names it lacks fall through.
  setenv("ROS_PACKAGE_PATH", ("/nonexistent:" + (dir_ / "ws/src/variational_formation/").string()).c_str(), 1);
  EXPECT_EQ(resolveScenario("hexagon"), (dir_ / "ws/src/variational_formation/config/hexagon.yaml").string());
  EXPECT_EQ(resolveScenario("square"), kSourceConfig + "/square.yaml");
}

TEST_F(ScenarioPathTest, AnExistingPathAlwaysWins) {
  write(dir_ / "hexagon", "a file named like a scenario");
  EXPECT_EQ(resolveScenario("hexagon"), "hexagon");
  EXPECT_EQ(resolveScenario(kSourceConfig + "/square.yaml"), kSourceConfig + "/square.yaml");
  // A folder is not a scenario file: the name is still looked up.
  fs::create_directories(dir_ / "square");
  EXPECT_EQ(resolveScenario("square"), kSourceConfig + "/square.yaml");
  // A path that does not exist is left for the loader to report.
  EXPECT_EQ(resolveScenario("no/such.yaml"), "no/such.yaml");
}

TEST_F(ScenarioPathTest, UnknownNameListsTheSearchPlaces) {
  setenv("ROS_PACKAGE_PATH", (dir_ / "ws").c_str(), 1);
  try {
    resolveScenario("hexagn");
    FAIL() << "an unknown name was accepted";
  } catch (const InvalidInput& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_EQ(what.rfind("scenario 'hexagn': no such file, and no hexagn.yaml in ", 0), 0u) << what;
    EXPECT_NE(what.find((dir_ / "ws/variational_formation/config").string()), std::string::npos) << what;
    EXPECT_NE(what.find(kSourceConfig), std::string::npos) << what;
  }
}

int runCli(int (*cli)(int, const char* const*, std::ostream&, std::ostream&), std::vector<std::string> args,
           std::string& err) {
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  std::ostringstream out, errors;
  const int status = cli(static_cast<int>(argv.size()), argv.data(), out, errors);
  err = errors.str();
  return status;
}

TEST_F(ScenarioPathTest, ToolsTakeNames) {
  std::string err;
  EXPECT_EQ(runCli(runSimulateCli, {"simulate", "--scenario", "square", "--out", "t.csv", "--steps", "3"}, err), 0)
      << err;
  std::ifstream traj("t.csv");
  std::string header;
  std::getline(traj, header);
  EXPECT_EQ(header, "step,t,agent,x,y,z");
  EXPECT_EQ(runCli(runSimulateCli, {"simulate", "--scenario", "hexagn", "--out", "t.csv"}, err), 2);
  EXPECT_EQ(err.rfind("simulate: error: scenario 'hexagn': no such file", 0), 0u) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
}

}  // namespace
}  // namespace vf
