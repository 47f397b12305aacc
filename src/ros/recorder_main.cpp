#include "variational_formation/ros/recorder_node.hpp"
#include "variational_formation/ros/node_main.hpp"

int main(int argc, char** argv) { return vf::runNode<vf::RecorderNode>(argc, argv, "recorder"); }
