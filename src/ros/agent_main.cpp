#include <string>

#include "variational_formation/ros/agent_node.hpp"
#include "variational_formation/ros/node_main.hpp"
#include "variational_formation/ros/timed_agent_node.hpp"

// ~mode: lockstep (AgentNode, the exact reference) or timed (TimedAgentNode, doc/robots.md).
int main(int argc, char** argv) {
  ros::init(argc, argv, "agent");
  std::string mode = "lockstep";
  ros::param::get("~mode", mode);
  if (mode == "timed") return vf::runNode<vf::TimedAgentNode>(argc, argv, "agent");
  if (mode != "lockstep") {
    ROS_FATAL("%s: ~mode: must be lockstep or timed, got '%s'", ros::this_node::getName().c_str(), mode.c_str());
    return 2;
  }
  return vf::runNode<vf::AgentNode>(argc, argv, "agent");
}
