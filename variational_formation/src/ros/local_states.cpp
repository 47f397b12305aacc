#include "variational_formation/ros/local_states.hpp"

#include <algorithm>
#include <atomic>
#include <memory>
#include <string>

#include "variational_formation/ros/participant_names.hpp"

namespace vf {

namespace {
std::unique_ptr<LocalStates::Exchange> gExchange;  // this process's, if it is an agent manager
std::string gNamespace;                            // its agents' namespace, as agent_0's full name
// By agent id: the queue each hosted agent runs on (read on every state handed over: no lock).
std::unique_ptr<std::atomic<ros::CallbackQueueInterface*>[]> gQueues;
std::size_t gQueueCount = 0;
}  // namespace

void LocalStates::start(const ros::NodeHandle& nh, const std::vector<int>& ids) {
  gNamespace = agentNodeName(nh, 0);
  gExchange = std::make_unique<Exchange>(ids);
  gQueueCount = ids.empty() ? 0 : static_cast<std::size_t>(*std::max_element(ids.begin(), ids.end())) + 1;
  gQueues.reset(new std::atomic<ros::CallbackQueueInterface*>[gQueueCount]);
  for (std::size_t k = 0; k < gQueueCount; ++k) gQueues[k] = nullptr;
}

void LocalStates::stop() {
  gExchange.reset();
  gQueues.reset();
  gQueueCount = 0;
}

void LocalStates::place(int id, ros::CallbackQueueInterface* queue) {
  if (id >= 0 && static_cast<std::size_t>(id) < gQueueCount) gQueues[static_cast<std::size_t>(id)] = queue;
}

ros::CallbackQueueInterface* LocalStates::queueOf(int id) {
  return id >= 0 && static_cast<std::size_t>(id) < gQueueCount ? gQueues[static_cast<std::size_t>(id)].load() : nullptr;
}

LocalStates::Exchange* LocalStates::of(const ros::NodeHandle& nh) {
  // A nodelet's handle spells the root namespace "" and a node's "/": compare full names.
  return gExchange && agentNodeName(nh, 0) == gNamespace ? gExchange.get() : nullptr;
}

}  // namespace vf
