#include "variational_formation/ros/node_main.hpp"
#include "variational_formation/ros/robot_sim_node.hpp"

int main(int argc, char** argv) { return vf::runNode<vf::RobotSimNode>(argc, argv, "robot_sim"); }
