#pragma once

#include <cstdio>
#include <cstring>
#include <string>
#include <type_traits>

#include <ros/ros.h>

namespace vf {

/**
 * True, with `usage` printed on stdout, when the command line asks for it (`--help` or `-h`):
 * main then exits 0. Checked before ros::init, so it needs no master.
 */
inline bool printedUsage(int argc, char** argv, const char* usage) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      std::fputs(usage, stdout);
      return true;
    }
  }
  return false;
}

/**
 * The whole main of a node: usage on --help (a generic line if `usage` is null), init,
 * construct (which reads and checks the parameters), run. A bad configuration is one ROS_FATAL
 * line and exit status 2; nothing escapes. A node whose run() returns an int exits with it.
 */
template <class Node>
int runNode(int argc, char** argv, const char* name, const char* usage = nullptr) {
  const std::string generic = std::string("usage: rosrun variational_formation ") + name +
                              " [ROS remappings and _param:=value]\n";
  if (printedUsage(argc, argv, usage != nullptr ? usage : generic.c_str())) return 0;
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
