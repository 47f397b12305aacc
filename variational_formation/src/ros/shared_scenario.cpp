#include "variational_formation/ros/shared_scenario.hpp"

#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

namespace vf {

namespace {
std::mutex gMutex;
std::map<std::string, std::shared_ptr<const Scenario>> gLoaded;                // by path and content
std::map<const Scenario*, std::shared_ptr<const Formation>> gFormations;  // by loaded scenario
}  // namespace

std::shared_ptr<const Scenario> sharedScenarioObject(const std::string& path) {
  std::ifstream file(path);
  std::ostringstream content;
  content << file.rdbuf();
  if (!file) return std::make_shared<const Scenario>(loadScenario(path));  // its error names the file
  const std::string key = path + '\n' + content.str();
  const std::lock_guard<std::mutex> lock(gMutex);
  const auto found = gLoaded.find(key);
  if (found != gLoaded.end()) return found->second;
  return gLoaded.emplace(key, std::make_shared<const Scenario>(loadScenario(path))).first->second;
}

Scenario sharedScenario(const std::string& path) { return *sharedScenarioObject(path); }

std::shared_ptr<const Formation> sharedFormation(const std::shared_ptr<const Scenario>& scenario) {
  const std::lock_guard<std::mutex> lock(gMutex);
  std::shared_ptr<const Formation>& formation = gFormations[scenario.get()];
  if (!formation) formation = std::make_shared<const Formation>(makeFormation(*scenario));
  return formation;
}

}  // namespace vf
