#pragma once

#include <type_traits>

#include <ros/ros.h>

namespace vf {

/**
 * The whole main of a node: init, construct (which reads and checks the parameters), run.
 * A bad configuration is one ROS_FATAL line and exit status 2; nothing escapes. A node whose
 * run() returns an int exits with it.
 */
template <class Node>
int runNode(int argc, char** argv, const char* name) {
  ros::init(argc, argv, name);
  ros::NodeHandle nh, pnh("~");
  try {
    Node node(nh, pnh);
    if constexpr (std::is_same<decltype(node.run()), int>::value) {
      return node.run();
    } else {
      node.run();
    }
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", ros::this_node::getName().c_str(), e.what());
    return 2;
  }
  return 0;
}

}  // namespace vf
