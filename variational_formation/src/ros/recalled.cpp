#include "variational_formation/ros/recalled.hpp"

#include "variational_formation_core/protocol/recovery.hpp"
#include "variational_formation/ros/participant_names.hpp"
#include "variational_formation/ros/service_call.hpp"

namespace vf {

Recalled recallNewest(const ros::NodeHandle& nh, int id, const std::vector<int>& neighbours, const std::string& monitor) {
  std::vector<std::string> holders;
  for (int j : neighbours) holders.push_back(agentNodeName(nh, j));
  holders.push_back(monitor);
  std::vector<std::string> services;
  for (const std::string& holder : holders) services.push_back(holder + "/recall");
  std::vector<variational_formation_msgs::RecallState> calls(holders.size());
  for (auto& call : calls) call.request.id = static_cast<uint32_t>(id);
  const std::vector<bool> answered = callAllWithTimeout(services, calls, 2.0);
  std::vector<protocol::RecallAnswer> answers;
  for (std::size_t k = 0; k < holders.size(); ++k) {
    answers.push_back({answered[k], answered[k] && calls[k].response.held, static_cast<long>(calls[k].response.step)});
  }
  Recalled r;
  const int k = protocol::chooseAgentResume(answers);
  if (k >= 0) {
    r.step = calls[static_cast<std::size_t>(k)].response.step;
    r.found = calls[static_cast<std::size_t>(k)].response;
    r.from = holders[static_cast<std::size_t>(k)];
  }
  return r;
}

}  // namespace vf
