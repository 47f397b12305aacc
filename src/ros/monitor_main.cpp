#include "variational_formation/ros/monitor_node.hpp"
#include "variational_formation/ros/node_main.hpp"

int main(int argc, char** argv) { return vf::runNode<vf::MonitorNode>(argc, argv, "monitor"); }
