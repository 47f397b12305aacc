// The lockstep agent's side of live commands (AgentNode, agent_node.hpp; doc/protocol.md
// "Commands"): the monitor's latched list of issued commands, applied in order by AgentProtocol.
#include "variational_formation/ros/agent_node.hpp"
#include "variational_formation/ros/formation_subscriptions.hpp"
#include "variational_formation/ros/participant_names.hpp"

namespace vf {

void AgentNode::onCommands(const ros::MessageEvent<variational_formation_msgs::FormationCommands const>& event) {
  if (!fromOwner(event, monitor_)) {
    drop("a command list from " + event.getPublisherName() + ", which is not the monitor " + monitor_);
    return;
  }
  const auto list = event.getConstMessage();
  carryOut(protocol_->step(Protocol::CommandsArrived{
      static_cast<long>(list->commands.size()), [&list](long k) {
        const variational_formation_msgs::FormationCommand& m = list->commands[static_cast<std::size_t>(k)];
        return protocol::IssuedCommand(m.step, commandOf(m));
      }}));
}

}  // namespace vf
