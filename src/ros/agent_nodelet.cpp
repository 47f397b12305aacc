// The lockstep agent as a nodelet: the same AgentNode as the agent node, on the nodelet's node
// handles, so that every agent loaded in one manager exchanges states as shared pointers
// (doc/distributed.md, "Nodelets").
#include <atomic>
#include <memory>
#include <thread>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "variational_formation/ros/agent_node.hpp"

namespace vf {

class AgentNodelet : public nodelet::Nodelet {
 public:
  ~AgentNodelet() override {
    if (asking_.joinable()) asking_.join();
  }

 private:
  void onInit() override {
    try {
      // Single-threaded handles: the manager runs this agent's callbacks one at a time, as the
      // node does, so AgentNode needs no lock.
      node_ = std::make_unique<AgentNode>(getNodeHandle(), getPrivateNodeHandle());
    } catch (const std::exception& e) {
      NODELET_FATAL("%s: %s", getName().c_str(), e.what());
      throw;  // the manager reports the load as failed
    }
    // Recovery asks the neighbours, some of them in this manager: ask from a thread of our own,
    // so that onInit returns at once and no worker of the manager waits on another.
    asking_ = std::thread([this] {
      const AgentNode::Recovery r = node_->askHolders();
      startTimer_ = getNodeHandle().createWallTimer(
          ros::WallDuration(0.0), [this, r](const ros::WallTimerEvent&) { node_->start(r); }, /*oneshot=*/true);
    });
  }

  std::unique_ptr<AgentNode> node_;
  std::thread asking_;
  ros::WallTimer startTimer_;
};

}  // namespace vf

PLUGINLIB_EXPORT_CLASS(vf::AgentNodelet, nodelet::Nodelet)
