#include "variational_formation/ros/shared_scenario.hpp"

#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

namespace vf {

Scenario sharedScenario(const std::string& path) {
  static std::mutex mutex;
  static std::map<std::string, Scenario> loaded;  // by path and content
  std::ifstream file(path);
  std::ostringstream content;
  content << file.rdbuf();
  if (!file) return loadScenario(path);  // its error names the file
  const std::string key = path + '\n' + content.str();
  const std::lock_guard<std::mutex> lock(mutex);
  const auto found = loaded.find(key);
  if (found != loaded.end()) return found->second;
  return loaded.emplace(key, loadScenario(path)).first->second;
}

}  // namespace vf
