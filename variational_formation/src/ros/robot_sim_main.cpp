#include "variational_formation/ros/node_main.hpp"
#include "variational_formation/ros/robot_sim_node.hpp"

namespace {
const char* const kUsage =
    "usage: rosrun variational_formation robot_sim [ROS remappings and _param:=value]\n"
    "One simulated holonomic robot: cmd_vel in; nav_msgs/Odometry on odom and tf out.\n"
    "Private parameters: ~id (required), ~initial_position, ~lag [s], ~odometry_noise [m], ~seed.\n"
    "Started per agent by robots.launch; see doc/robots.md.\n";
}  // namespace

int main(int argc, char** argv) { return vf::runNode<vf::RobotSimNode>(argc, argv, "robot_sim", kUsage); }
