// The lockstep agent as a nodelet: the same AgentNode as the agent node, on the nodelet's node
// handles, so that every agent loaded in one manager exchanges states as shared pointers
// (doc/distributed.md, "Nodelets").
#include <atomic>
#include <memory>
#include <thread>

#include <nodelet/nodelet.h>
#include <ros/callback_queue_interface.h>
#include <pluginlib/class_list_macros.hpp>

#include "variational_formation/ros/agent_node.hpp"
#include "variational_formation/ros/state_batch.hpp"

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
      ros::NodeHandle nh = getNodeHandle(), pnh = getPrivateNodeHandle();
      if (AgentThreads* threads = AgentThreads::local()) {  // in an agent_manager: its own threads
        ros::CallbackQueue* queue = threads->nextQueue();
        nh.setCallbackQueue(queue);
        pnh.setCallbackQueue(queue);
      }
      queue_ = nh.getCallbackQueue();
      node_ = std::make_unique<AgentNode>(nh, pnh);
    } catch (const std::exception& e) {
      NODELET_FATAL("%s: %s", getName().c_str(), e.what());
      throw;  // the manager reports the load as failed
    }
    // Recovery asks the neighbours, some of them in this manager: ask from a thread of our own,
    // so that onInit returns at once and no worker of the manager waits on another.
    // The start then runs as one callback on the agent's queue: not a one-shot timer, which
    // would stay among the process's timers, each of which makes every timer that fires slower.
    asking_ = std::thread([this] {
      const AgentNode::Recovery r = node_->askHolders();
      queue_->addCallback(boost::make_shared<Start>(node_.get(), r), reinterpret_cast<uint64_t>(this));
    });
  }

  /// node->start(recovery), once, on the queue it is added to.
  class Start : public ros::CallbackInterface {
   public:
    Start(AgentNode* node, AgentNode::Recovery recovery) : node_(node), recovery_(std::move(recovery)) {}
    CallResult call() override {
      node_->start(recovery_);
      return Success;
    }

   private:
    AgentNode* node_;
    AgentNode::Recovery recovery_;
  };

  std::unique_ptr<AgentNode> node_;
  ros::CallbackQueueInterface* queue_ = nullptr;  // where the agent's callbacks run
  std::thread asking_;
};

}  // namespace vf

PLUGINLIB_EXPORT_CLASS(vf::AgentNodelet, nodelet::Nodelet)
