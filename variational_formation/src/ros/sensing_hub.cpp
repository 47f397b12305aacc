#include "variational_formation/ros/sensing_hub.hpp"

#include <map>
#include <mutex>

#include "variational_formation_msgs/AgentState.h"
#include "variational_formation/ros/participant_names.hpp"
#include "variational_formation/ros/state_batch.hpp"

namespace vf {

namespace {

struct Hub {
  std::shared_ptr<SensingBoard> board;
  std::vector<ros::Subscriber> subscribers;
};

std::mutex gMutex;
std::map<std::string, Hub> gHubs;  // by formation namespace

}  // namespace

std::shared_ptr<SensingBoard> SensingHub::board(ros::NodeHandle& nh, const Scenario& scenario,
                                                const std::vector<std::string>& managers) {
  StateBatch* batch = StateBatch::local();
  if (!batch || !scenario.safety) return nullptr;
  std::lock_guard<std::mutex> lock(gMutex);
  Hub& hub = gHubs[nh.getNamespace()];
  if (hub.board) return hub.board;
  hub.board = std::make_shared<SensingBoard>(scenario.agentCount(), scenario.dimension, scenario.safety->sensingRadius);
  ros::NodeHandle global(nh.getNamespace());  // the global queue, which the manager spins
  for (int j = 0; j < scenario.agentCount(); ++j) {
    if (batch->ids().count(j)) continue;  // its own agents put their states on the board themselves
    const std::string owner = agentNodeName(nh, j);
    std::weak_ptr<SensingBoard> weak = hub.board;
    hub.subscribers.push_back(global.subscribe<variational_formation_msgs::AgentState>(
        "agent_" + std::to_string(j) + "/state", 1000,
        boost::function<void(const ros::MessageEvent<variational_formation_msgs::AgentState const>&)>(
            [weak, owner, managers, j](const ros::MessageEvent<variational_formation_msgs::AgentState const>& e) {
              const auto& msg = *e.getConstMessage();
              const auto board = weak.lock();
              const std::size_t d = board ? static_cast<std::size_t>(board->dimension()) : 0;
              if (!board || !fromAgent(e, owner, managers) || static_cast<int>(msg.id) != j ||
                  msg.position.size() != d || msg.previous_position.size() != d) {
                ROS_WARN_THROTTLE(1.0, "sensing: dropped a state on agent_%d's topic from %s", j,
                                  e.getPublisherName().c_str());
                return;
              }
              board->offer(j, msg.step, msg.position.data(), msg.previous_position.data());
            }),
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
  }
  return hub.board;
}

void SensingHub::stop() {
  std::lock_guard<std::mutex> lock(gMutex);
  gHubs.clear();
}

}  // namespace vf
