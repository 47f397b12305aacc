#include "variational_formation/ros/mujoco_world_node.hpp"
#include "variational_formation/ros/node_main.hpp"

namespace {
const char* const kUsage =
    "usage: rosrun variational_formation mujoco_world _scenario:=FILE [_kinematics:=unicycle] [_param:=value]\n"
    "Every robot of a planar scenario in one MuJoCo world, each with robot_sim's interface in robot_<i>:\n"
    "cmd_vel in; odom, joint_states and tf out; contacts on ~contacts, bodies, headings, obstacles\n"
    "and contacts for rviz on ~markers. The scenario's obstacles are static geoms. Started by\n"
    "robots.launch world:=mujoco; parameters in doc/ros_api.md, the model in doc/robots.md.\n";
}  // namespace

int main(int argc, char** argv) { return vf::runNode<vf::MujocoWorldNode>(argc, argv, "mujoco_world", kUsage); }
