// The recorder's side of live commands (RecorderNode, recorder_node.hpp; doc/protocol.md
// "Commands"): the monitor's list of issued commands into the bag, each just before the step it
// applies from, and the whole applied schedule into ~commands_file, a `simulate --commands` file.
#include <algorithm>
#include <cstdio>
#include <sstream>

#include "variational_formation_core/protocol/command_desk.hpp"
#include "variational_formation/ros/output_files.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/formation_subscriptions.hpp"
#include "variational_formation/ros/participant_names.hpp"
#include "variational_formation/ros/recorder_node.hpp"

namespace vf {

void RecorderNode::setUpCommands(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  commandsTopic_ = BagWriter::Topic(nh.resolveName("command"));
  commandsFile_ = optionalParam<std::string>(pnh, "commands_file", "");
  if (!commandsFile_.empty()) {
    commandsFile_ = outputPath(nh, commandsFile_);
    createParentDirectory(commandsFile_, "~commands_file");
    std::remove(commandsFile_.c_str());  // an earlier run's
    writeCommandsFile();
  }
  subs_.push_back(nh.subscribe<variational_formation_msgs::FormationCommands>(
      "command", 10,
      boost::function<void(const ros::MessageEvent<variational_formation_msgs::FormationCommands const>&)>(
          [this](const ros::MessageEvent<variational_formation_msgs::FormationCommands const>& e) { onCommands(e); }),
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
}

void RecorderNode::onCommands(const ros::MessageEvent<variational_formation_msgs::FormationCommands const>& event) {
  if (!fromOwner(event, monitor_)) {
    ++dropped_;
    ROS_WARN_THROTTLE(1.0, "recorder: dropped a command list from %s, which is not the monitor %s",
                      event.getPublisherName().c_str(), monitor_.c_str());
    return;
  }
  std::vector<long> stamps;
  for (const auto& m : event.getConstMessage()->commands) stamps.push_back(m.step);
  const Protocol::Ready ready = protocol_->step(Protocol::CommandsArrived{stamps});
  if (ready.takeCommands) {  // the newest list (an older copy that arrives late is not)
    commands_ = *event.getConstMessage();
    writeCommandsFile();
  }
  carryOut(ready);  // steps that waited for these commands
}

void RecorderNode::writeCommandsFile() const {
  if (commandsFile_.empty()) return;
  std::vector<protocol::IssuedCommand> issued;
  for (const auto& m : commands_.commands) issued.emplace_back(m.step, commandOf(m));
  const CommandSchedule schedule = protocol::appliedSchedule(scenario_, issued);
  if (schedule.empty()) return;  // no manoeuvre and no command: nothing to replay
  std::ostringstream text;
  writeCommands(text, schedule);
  if (!replaceFileWith(commandsFile_, text.str())) ROS_ERROR("recorder: cannot write %s", commandsFile_.c_str());
}

}  // namespace vf
