// What a lockstep agent senses with `safety:` (AgentNode, agent_node.hpp; doc/distributed.md
// "Sensing"): whose states it takes, the board's wake-up, and the agents of other formations it
// keeps r from (doc/maths.md §10, "Other formations").
#include "variational_formation/ros/agent_node.hpp"

#include <ros/callback_queue.h>

#include "variational_formation/ros/pacer.hpp"

namespace vf {

void AgentNode::avoidOtherFormations(const ros::NodeHandle& nh, const ros::NodeHandle& pnh, LockstepAgent& agent) {
  const Scenario& scenario = agent.scenario();
  if (!scenario.safety) return;
  foreign_ = ForeignFormations::watch(nh, avoidParameter(pnh), scenario.dimension);
  if (foreign_) agent.avoid(foreign_->agents());
}

std::vector<int> AgentNode::sources() const {
  if (!agent().board() || sharedBoard_) return agent().neighbourIds();
  std::vector<int> all;
  for (int j = 0; j < agent().scenario().agentCount(); ++j) {
    if (j != agent().id()) all.push_back(j);
  }
  return all;
}

void AgentNode::wakeWhenSensed() {
  if (!sharedBoard_ || wakeStep_ == agent().step()) return;
  wakeStep_ = agent().step();
  ros::CallbackQueueInterface* queue = nh_.getCallbackQueue();
  const std::shared_ptr<bool> alive = alive_;
  agent().board()->whenComplete(agent().step(), [this, queue, alive] {
    queue->addCallback(boost::make_shared<QueuedCall>([this, alive] {
      if (*alive) carryOut(protocol_->step(Protocol::Wake{}));
    }), reinterpret_cast<uint64_t>(this));
  });
}

}  // namespace vf
