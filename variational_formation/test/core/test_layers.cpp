// Layer guard: the core package (variational_formation_core: include/, src/) includes only the
// standard library, Eigen, yaml-cpp and other core headers. A compile-time guard is not
// possible on Debian, where ROS headers share /usr/include with Eigen, so this test reads
// every core file and checks each #include against that allowlist, and reads the built core
// library's link dependencies (what the core's package.xml and CMake declare is checked by
// test/package/test_dependencies.py). The last test is a layout rule: headers named after a class.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

/// Whether a core file may include `target` (the text between <> or "").
bool allowedInCore(const std::string& target) {
  static const std::regex standardLibrary("[a-z_0-9]+");  // <vector>, <cmath>: no '/' or '.'
  static const std::regex eigen("(Eigen|unsupported/Eigen)/[A-Za-z0-9_]+");
  static const std::regex yamlCpp("yaml-cpp/[A-Za-z0-9_/]+\\.h");
  static const std::regex core("variational_formation_core/[a-z_0-9]+/[a-z_0-9]+\\.hpp");  // <concept>/<file>
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
                          "pluginlib/class_list_macros.h", "ros.h", "variational_formation_msgs/AgentState.h",
                          "variational_formation/ros/markers.hpp", "variational_formation/core/formation.hpp",
                          "variational_formation/tools/arguments.hpp", "boost/shared_ptr.hpp", "MACRO"}) {
    EXPECT_FALSE(allowedInCore(ros)) << ros;
  }
  for (const char* ok : {"vector", "cmath", "Eigen/Dense", "Eigen/Eigenvalues", "yaml-cpp/yaml.h",
                         "variational_formation_core/model/formation.hpp"}) {
    EXPECT_TRUE(allowedInCore(ok)) << ok;
  }
}

/// The core package's folder, beside this package's in the repository.
fs::path coreRoot() { return fs::path(VF_SOURCE_DIR) / ".." / "variational_formation_core"; }

TEST(LayerGuard, CoreIncludesNothingFromRos) {
  int files = 0;
  std::vector<Include> includes = includesUnder(coreRoot() / "include", files);
  const std::vector<Include> sources = includesUnder(coreRoot() / "src", files);
  includes.insert(includes.end(), sources.begin(), sources.end());
  // A wrong path would make this test pass vacuously.
  EXPECT_GE(files, 20);
  EXPECT_GE(includes.size(), 50u);
  for (const Include& inc : includes) {
    EXPECT_TRUE(allowedInCore(inc.target))
        << inc.file << ":" << inc.line << ": core includes '" << inc.target
        << "'; the core may include only the standard library, Eigen, yaml-cpp and "
           "variational_formation_core headers";
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

// The include guard above reads the text; this reads what the linker made of the core: the
// shared libraries the built libvariational_formation_core.so needs (readelf, binutils, which
// every C++ build has). A ROS library linked in by CMake (catkin_LIBRARIES, roscpp) fails here
// even if no core file includes a ROS header.
TEST(LayerGuard, CoreLibraryLinksOnlyYamlCppAndTheSystem) {
  const std::string library = VF_CORE_LIBRARY;
  ASSERT_TRUE(fs::exists(library)) << library;
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(("readelf -d '" + library + "' 2>&1").c_str(), "r"), pclose);
  ASSERT_TRUE(pipe);
  static const std::regex needed(R"(.*\(NEEDED\).*\[(.+)\].*)");
  static const std::regex allowed(R"((libyaml-cpp|libstdc\+\+|libm|libgcc_s|libc|libpthread)\.so.*)");
  char buffer[512];
  std::vector<std::string> libraries;
  while (fgets(buffer, sizeof buffer, pipe.get())) {
    std::smatch m;
    std::string line(buffer);
    if (!line.empty() && line.back() == '\n') line.pop_back();
    if (std::regex_match(line, m, needed)) libraries.push_back(m[1].str());
  }
  // Not vacuous: the core uses yaml-cpp and the C++ library.
  EXPECT_GE(libraries.size(), 2u);
  for (const std::string& name : libraries) {
    EXPECT_TRUE(std::regex_match(name, allowed))
        << library << " needs " << name << ": the core links only yaml-cpp, threads and the C++ runtime";
  }
}

/// The classes and structs a header declares at namespace scope (not nested, not forward).
std::vector<std::string> declaredTypes(const fs::path& header) {
  static const std::regex declaration(R"(^(class|struct)\s+([A-Za-z_0-9]+)(\s+final)?\s*([:{].*)?$)");
  std::vector<std::string> names;
  std::ifstream in(header);
  std::string line;
  while (std::getline(in, line)) {
    std::smatch m;
    if (std::regex_match(line, m, declaration)) names.push_back(m[2].str());
  }
  return names;
}

/// file_name -> FileName.
std::string camelCase(const std::string& stem) {
  std::string out;
  bool upper = true;
  for (char c : stem) {
    if (c == '_') {
      upper = true;
    } else {
      out += upper ? static_cast<char>(std::toupper(static_cast<unsigned char>(c))) : c;
      upper = false;
    }
  }
  return out;
}

// A header that declares classes or structs is named after one of them (lockstep_referee.hpp
// holds LockstepReferee), in both packages' include folders. The files below hold a family of
// types or functions with no one main class (the explicit integrators, the recovery answers, the
// rigidity tests); a new mismatch fails, and so does an entry here once its file is renamed.
TEST(LayerGuard, HeadersAreNamedAfterAClassTheyDeclare) {
  const std::map<std::string, std::string> exceptions = {
      {"variational_formation_core/integrators/explicit_integrators.hpp", "ExplicitEulerIntegrator, RungeKutta4Integrator"},
      {"variational_formation_core/protocol/recovery.hpp", "RecorderBuffers, MonitorResume"},
      {"variational_formation_core/model/rigidity.hpp", "RigidityReport"},
      {"variational_formation_core/robots/robot_mode.hpp", "RobotLoopSettings"},
      {"variational_formation_core/safety/safety_filter.hpp", "SafeStep"},
      {"variational_formation_core/model/validation.hpp", "FieldNames, ScenarioOverrides"},
      {"variational_formation_core/integrators/variational_update.hpp", "VariationalCoefficients"},
      {"variational_formation_core/generators/formation_generators.hpp", "FormationGraph"},
      {"variational_formation/ros/service_call.hpp", "CallPool"},
      {"variational_formation/world/mjcf_model.hpp", "StaticObstacle"},
  };

  std::set<std::string> mismatched;
  int headers = 0;
  for (const fs::path& root : {fs::path(VF_SOURCE_DIR) / "include", coreRoot() / "include"}) {
    for (const auto& entry : fs::recursive_directory_iterator(root)) {
      if (entry.path().extension() != ".hpp") continue;
      ++headers;
      const std::vector<std::string> types = declaredTypes(entry.path());
      const std::string expected = camelCase(entry.path().stem().string());
      if (types.empty() || std::find(types.begin(), types.end(), expected) != types.end()) continue;
      const std::string relative = fs::relative(entry.path(), root).generic_string();
      mismatched.insert(relative);
      EXPECT_TRUE(exceptions.count(relative))
          << relative << " declares " << types.front() << " (and " << types.size() - 1
          << " more) but no " << expected << ": name the file after its main class";
    }
  }
  EXPECT_GE(headers, 60);  // the right folder
  for (const auto& [file, holds] : exceptions) {
    EXPECT_TRUE(mismatched.count(file)) << file << " (" << holds << ") now matches or is gone: remove it from the list";
  }
  // The rule itself: a header holding only LockstepReferee must not pass as run_referee.hpp.
  EXPECT_EQ(camelCase("run_referee"), "RunReferee");
  EXPECT_EQ(camelCase("force_model"), "ForceModel");
}

}  // namespace
