#include "variational_formation/tools/scenario_path.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "variational_formation_core/common/invalid_input.hpp"

namespace vf {

namespace {
bool isFile(const std::string& path) {
  std::error_code ignored;
  return std::filesystem::is_regular_file(path, ignored);
}

void add(std::vector<std::string>& folders, const std::string& folder) {
  if (!folder.empty() && std::find(folders.begin(), folders.end(), folder) == folders.end()) {
    folders.push_back(folder);
  }
}
}  // namespace

std::vector<std::string> scenarioFolders() {
  std::vector<std::string> folders;
  if (const char* path = std::getenv("ROS_PACKAGE_PATH")) {
    std::istringstream entries(path);
    for (std::string entry; std::getline(entries, entry, ':');) {
      while (entry.size() > 1 && entry.back() == '/') entry.pop_back();
      if (entry.empty()) continue;
      const bool isPackage = std::filesystem::path(entry).filename() == "variational_formation";
      add(folders, isPackage ? entry + "/config" : entry + "/variational_formation/config");
    }
  }
  // Beside the running program, so that nothing about the build's folders is compiled in (the
  // install space must not name the workspace): an installed tool lives in
  // <prefix>/lib/variational_formation beside <prefix>/share/variational_formation, and a devel
  // one in <ws>/devel/lib/variational_formation beside the sources in <ws>/src.
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const std::filesystem::path prefix = exe.parent_path() / ".." / "..";
    add(folders, (prefix / "share" / "variational_formation" / "config").lexically_normal().string());
    add(folders, (prefix / ".." / "src" / "variational_formation" / "config").lexically_normal().string());
  }
  return folders;
}

std::string resolveScenario(const std::string& nameOrPath) {
  if (isFile(nameOrPath) || nameOrPath.find('/') != std::string::npos || nameOrPath.empty()) return nameOrPath;
  const bool hasSuffix = nameOrPath.size() > 5 && nameOrPath.compare(nameOrPath.size() - 5, 5, ".yaml") == 0;
  const std::string file = hasSuffix ? nameOrPath : nameOrPath + ".yaml";
  const std::vector<std::string> folders = scenarioFolders();
  std::string places;
  for (const std::string& folder : folders) {
    if (isFile(folder + "/" + file)) return folder + "/" + file;
    places += (places.empty() ? "" : ", ") + folder;
  }
  throw InvalidInput("scenario '" + nameOrPath + "': no such file, and no " + file + " in " + places);
}

}  // namespace vf
