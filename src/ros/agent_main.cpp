#include "variational_formation/ros/agent_node.hpp"
#include "variational_formation/ros/node_main.hpp"

int main(int argc, char** argv) { return vf::runNode<vf::AgentNode>(argc, argv, "agent"); }
