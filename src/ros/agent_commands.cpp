// The lockstep agent's side of live commands (AgentNode, agent_node.hpp; doc/protocol.md
// "Commands"): the monitor's latched list of issued commands, applied in order.
#include "variational_formation/ros/agent_node.hpp"
#include "variational_formation/ros/participants.hpp"

namespace vf {

void AgentNode::onCommands(const ros::MessageEvent<variational_formation::FormationCommands const>& event) {
  if (!fromOwner(event, monitor_)) {
    drop("a command list from " + event.getPublisherName() + ", which is not the monitor " + monitor_);
    return;
  }
  const auto& list = event.getConstMessage()->commands;
  while (failure_.empty() && commandsHeld_ < static_cast<long>(list.size())) {
    const variational_formation::FormationCommand& m = list[static_cast<std::size_t>(commandsHeld_)];
    std::string error;
    const LockstepAgent::CommandReceipt receipt = agent_->receiveCommand(m.step, commandOf(m), &error);
    if (receipt != LockstepAgent::CommandReceipt::Accepted) {
      // The monitor checked it and stamped it at a step no agent had passed: this cannot be made
      // exact any more, so the run ends, saying why.
      failure_ = "command " + std::to_string(commandsHeld_ + 1) + " (from step " + std::to_string(m.step) +
                 ") refused at step " + std::to_string(agent_->step()) + ": " +
                 (receipt == LockstepAgent::CommandReceipt::Late ? std::string("it came after that step") : error);
      ROS_ERROR("%s: %s; ending the run", name_.c_str(), failure_.c_str());
      publish();
      return;
    }
    ++commandsHeld_;
  }
  tryAdvance();
}

}  // namespace vf
