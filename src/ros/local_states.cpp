#include "variational_formation/ros/local_states.hpp"

#include <memory>
#include <string>

#include "variational_formation/ros/participants.hpp"

namespace vf {

namespace {
std::unique_ptr<LocalStates::Exchange> gExchange;  // this process's, if it is an agent manager
std::string gNamespace;                            // its agents' namespace, as agent_0's full name
}  // namespace

void LocalStates::start(const ros::NodeHandle& nh, const std::vector<int>& ids) {
  gNamespace = agentNodeName(nh, 0);
  gExchange = std::make_unique<Exchange>(ids);
}

void LocalStates::stop() { gExchange.reset(); }

LocalStates::Exchange* LocalStates::of(const ros::NodeHandle& nh) {
  // A nodelet's handle spells the root namespace "" and a node's "/": compare full names.
  return gExchange && agentNodeName(nh, 0) == gNamespace ? gExchange.get() : nullptr;
}

}  // namespace vf
