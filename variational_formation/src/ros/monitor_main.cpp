#include "variational_formation/ros/monitor_node.hpp"
#include "variational_formation/ros/node_main.hpp"

namespace {
const char* const kUsage =
    "usage: rosrun variational_formation monitor [ROS remappings and _param:=value]\n"
    "The referee of a lockstep or timed formation run: starts the agents once all are there,\n"
    "publishes status, markers and progress, and writes the result file.\n"
    "Private parameters: ~scenario (required), ~result_file, ~window, ~recorder, ~mode,\n"
    "~real_time_factor, ~wait_for_viewer, ~agent_manager, ~marker_every, ~respawn_timeout.\n"
    "Started by formation.launch; topics and services: doc/architecture.md.\n";

/// The monitor of the mode its ~mode parameter names.
class Monitor {
 public:
  Monitor(ros::NodeHandle& nh, ros::NodeHandle& pnh) : node_(vf::makeMonitor(nh, pnh)) {}
  int run() { return node_->run(); }

 private:
  std::unique_ptr<vf::MonitorNode> node_;
};
}  // namespace

int main(int argc, char** argv) { return vf::runNode<Monitor>(argc, argv, "monitor", kUsage); }
