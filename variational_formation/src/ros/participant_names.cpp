#include "variational_formation/ros/participant_names.hpp"

#include <sstream>

namespace vf {

std::string agentNodeName(const ros::NodeHandle& nh, int id) {
  return participantName(nh, "agent_" + std::to_string(id));
}

std::string participantName(const ros::NodeHandle& nh, const std::string& relative) {
  return nh.resolveName(relative, /*remap=*/false);
}

std::vector<std::string> agentManagers(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) {
  std::string list;
  pnh.param<std::string>("agent_manager", list, "");
  std::istringstream words(list);
  std::vector<std::string> managers;
  for (std::string w; words >> w;) managers.push_back(participantName(nh, w));
  return managers;
}

}  // namespace vf
