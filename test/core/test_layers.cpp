// Layer guard: the core (include/variational_formation/core, src/core) includes only the
// standard library, Eigen, yaml-cpp and other core headers. A compile-time guard is not
// possible on Debian, where ROS headers share /usr/include with Eigen, so this test reads
// every core file and checks each #include against that allowlist.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

/// Whether a core file may include `target` (the text between <> or "").
bool allowedInCore(const std::string& target) {
  static const std::regex standardLibrary("[a-z_0-9]+");  // <vector>, <cmath>: no '/' or '.'
  static const std::regex eigen("(Eigen|unsupported/Eigen)/[A-Za-z0-9_]+");
  static const std::regex yamlCpp("yaml-cpp/[A-Za-z0-9_/]+\\.h");
  static const std::regex core("variational_formation/core/([a-z_0-9]+/)?[a-z_0-9]+\\.hpp");  // and core/protocol/
  return std::regex_match(target, standardLibrary) || std::regex_match(target, eigen) ||
         std::regex_match(target, yamlCpp) || std::regex_match(target, core);
}

struct Include {
  std::string file;
  int line;
  std::string target;  ///< the included name, or the whole directive if it names none
};

/// Every #include directive of the files under `dir` (recursively).
std::vector<Include> includesUnder(const fs::path& dir, int& files) {
  static const std::regex directive(R"(^\s*#\s*include\b\s*(.*)$)");
  static const std::regex quoted(R"(^[<"]([^>"]+)[>"].*$)");
  std::vector<Include> found;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    ++files;
    std::ifstream in(entry.path());
    std::string text;
    for (int line = 1; std::getline(in, text); ++line) {
      std::smatch m, name;
      if (!std::regex_match(text, m, directive)) continue;
      const std::string rest = m[1].str();
      found.push_back({entry.path().string(), line,
                       std::regex_match(rest, name, quoted) ? name[1].str() : rest});
    }
  }
  return found;
}

TEST(LayerGuard, TheAllowlistRejectsRosAndOtherLayers) {
  // The guard below is only as good as this predicate: it must refuse every kind of ROS
  // header, the generated message headers and the package's other layers.
  for (const char* ros : {"ros/ros.h", "ros/time.h", "tf2/LinearMath/Quaternion.h", "tf2_ros/buffer.h",
                          "tf2_msgs/TFMessage.h", "geometry_msgs/Point.h", "std_msgs/Header.h",
                          "visualization_msgs/MarkerArray.h", "rosbag/bag.h", "nodelet/nodelet.h",
                          "pluginlib/class_list_macros.h", "ros.h", "variational_formation/AgentState.h",
                          "variational_formation/ros/markers.hpp",
                          "variational_formation/tools/arguments.hpp", "boost/shared_ptr.hpp", "MACRO"}) {
    EXPECT_FALSE(allowedInCore(ros)) << ros;
  }
  for (const char* ok : {"vector", "cmath", "Eigen/Dense", "Eigen/Eigenvalues", "yaml-cpp/yaml.h",
                         "variational_formation/core/formation.hpp"}) {
    EXPECT_TRUE(allowedInCore(ok)) << ok;
  }
}

TEST(LayerGuard, CoreIncludesNothingFromRos) {
  const fs::path root(VF_SOURCE_DIR);
  int files = 0;
  std::vector<Include> includes = includesUnder(root / "include/variational_formation/core", files);
  const std::vector<Include> sources = includesUnder(root / "src/core", files);
  includes.insert(includes.end(), sources.begin(), sources.end());
  // A wrong path would make this test pass vacuously.
  EXPECT_GE(files, 20);
  EXPECT_GE(includes.size(), 50u);
  for (const Include& inc : includes) {
    EXPECT_TRUE(allowedInCore(inc.target))
        << inc.file << ":" << inc.line << ": core includes '" << inc.target
        << "'; the core may include only the standard library, Eigen, yaml-cpp and "
           "variational_formation/core headers";
  }
}

// The MuJoCo world (world/) is ROS-free too: what the core may include, the core itself,
// MuJoCo's header and its own headers.
TEST(LayerGuard, WorldIncludesNothingFromRos) {
  const fs::path root(VF_SOURCE_DIR);
  static const std::regex world("variational_formation/world/[a-z_0-9]+\\.hpp");
  int files = 0;
  std::vector<Include> includes = includesUnder(root / "include/variational_formation/world", files);
  const std::vector<Include> sources = includesUnder(root / "src/world", files);
  includes.insert(includes.end(), sources.begin(), sources.end());
  EXPECT_GE(files, 10);  // not vacuous
  for (const Include& inc : includes) {
    EXPECT_TRUE(allowedInCore(inc.target) || inc.target == "mujoco/mujoco.h" || std::regex_match(inc.target, world))
        << inc.file << ":" << inc.line << ": the world includes '" << inc.target << "'";
  }
}

}  // namespace
