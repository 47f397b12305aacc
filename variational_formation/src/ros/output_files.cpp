#include "variational_formation/ros/output_files.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "variational_formation_core/common/invalid_input.hpp"

namespace vf {

namespace {
bool exists(const std::string& path) { return std::ifstream(path).good(); }
}  // namespace

std::string namespaceFilePrefix(const ros::NodeHandle& nh) {
  std::string ns = nh.getNamespace();
  const std::size_t slash = ns.rfind('/');
  ns = slash == std::string::npos ? "" : ns.substr(0, slash);  // the namespace holding the formation
  while (!ns.empty() && ns.front() == '/') ns.erase(0, 1);
  for (char& c : ns) c = c == '/' ? '_' : c;
  return ns.empty() ? "" : ns + "_";
}

std::string outputPath(const ros::NodeHandle& nh, const std::string& path) {
  const std::string token = "{ns}";
  std::string out = path;
  for (std::size_t at = out.find(token); at != std::string::npos; at = out.find(token, at)) {
    const std::string prefix = namespaceFilePrefix(nh);
    out.replace(at, token.size(), prefix);
    at += prefix.size();
  }
  return out;
}

void announceReplacedResult(const std::string& path) {
  std::ifstream f(path);
  std::string first;
  if (!f || !std::getline(f, first) || first == "result: running") return;
  ROS_WARN("monitor: replacing the result of an earlier run in %s (%s)", path.c_str(), first.c_str());
}

bool replaceFileWith(const std::string& path, const std::string& text) {
  const std::string partial = path + ".partial";
  {
    std::ofstream f(partial);
    f << text;
    if (!f) return false;
  }
  return std::rename(partial.c_str(), path.c_str()) == 0;
}

Appended appendToResult(const std::string& path, const std::string& lines) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  const std::string body = text.str();
  if (body.find("result: ") == std::string::npos || body.find("result: running") != std::string::npos) return Appended::notYet;
  if (replaceFileWith(path, body + lines)) return Appended::done;
  ROS_ERROR("%s: cannot add to the result file %s", ros::this_node::getName().c_str(), path.c_str());
  return Appended::failed;
}

void replaceEarlierBag(const std::string& path) {
  if (!exists(path)) return;
  const bool named = path.size() > 4 && path.compare(path.size() - 4, 4, ".bag") == 0;
  const std::string stem = named ? path.substr(0, path.size() - 4) : path;
  int removed = 0;
  for (int part = 1; exists(stem + "_" + std::to_string(part) + ".bag"); ++part) {
    if (std::remove((stem + "_" + std::to_string(part) + ".bag").c_str()) == 0) ++removed;
  }
  ROS_WARN("recorder: replacing the bag of an earlier run %s%s", path.c_str(),
           removed > 0 ? (" (its " + std::to_string(removed) + " later parts removed)").c_str() : "");
}

void createParentDirectory(const std::string& path, const std::string& parameter) {
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (dir.empty()) return;
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw InvalidInput(parameter + ": cannot create the directory '" + dir.string() + "': " + error.message());
}

}  // namespace vf
