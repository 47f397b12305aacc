#include <string>

#include "variational_formation/ros/agent_node.hpp"
#include "variational_formation/ros/node_main.hpp"
#include "variational_formation/ros/timed_agent_node.hpp"

namespace {
const char* const kUsage =
    "usage: rosrun variational_formation agent [ROS remappings and _param:=value]\n"
    "One agent of a formation: integrates its own state from its neighbours' states.\n"
    "Private parameters: ~id and ~scenario (required), ~mode (lockstep or timed),\n"
    "~real_time_factor, ~monitor, ~agent_manager; timed mode also ~delay, ~jitter, ~loss,\n"
    "~max_age, ~seed, ~robot.\n"
    "Started by agent.launch (one per agent); see doc/distributed.md and doc/robots.md.\n";
}  // namespace

// ~mode: lockstep (AgentNode, the exact reference) or timed (TimedAgentNode, doc/robots.md).
int main(int argc, char** argv) {
  if (vf::printedUsage(argc, argv, kUsage)) return 0;
  ros::init(argc, argv, "agent");
  std::string mode = "lockstep";
  ros::param::get("~mode", mode);
  if (mode == "timed") return vf::runNode<vf::TimedAgentNode>(argc, argv, "agent", kUsage);
  if (mode != "lockstep") {
    ROS_FATAL("%s: ~mode: must be lockstep or timed, got '%s'", ros::this_node::getName().c_str(), mode.c_str());
    return 2;
  }
  return vf::runNode<vf::AgentNode>(argc, argv, "agent", kUsage);
}
