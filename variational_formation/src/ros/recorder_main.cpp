#include "variational_formation/ros/recorder_node.hpp"
#include "variational_formation/ros/node_main.hpp"

namespace {
const char* const kUsage =
    "usage: rosrun variational_formation recorder [ROS remappings and _param:=value]\n"
    "Records a formation run to a bag, each state, status and step's markers once, in step order.\n"
    "Private parameters: ~scenario and ~bag (required), ~max_size, ~split_size [MB],\n"
    "~marker_every, ~agent_manager.\n"
    "Started by formation.launch record:=true; topics: doc/architecture.md.\n";
}  // namespace

int main(int argc, char** argv) { return vf::runNode<vf::RecorderNode>(argc, argv, "recorder", kUsage); }
