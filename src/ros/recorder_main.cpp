#include <ros/ros.h>

#include "variational_formation/ros/recorder_node.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "recorder");
  ros::NodeHandle nh, pnh("~");
  try {
    vf::RecorderNode node(nh, pnh);
    node.run();
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", ros::this_node::getName().c_str(), e.what());
    return 2;
  }
  return 0;
}
