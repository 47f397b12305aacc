// Live commands (MonitorNode, monitor_node.hpp; doc/protocol.md "Commands"): cmd_vel and scale
// in, checked by core's CommandDesk, which stamps them; the list of issued commands out on the
// latched `command`, kept on the parameter server first. When they are issued is the mode's.
#include <sstream>

#include "variational_formation_msgs/FormationCommands.h"
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation/ros/monitor_node.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/participant_names.hpp"

namespace vf {

namespace {


variational_formation_msgs::FormationCommands toMessage(const std::vector<protocol::IssuedCommand>& issued,
                                                   const ros::Time& stamp) {
  variational_formation_msgs::FormationCommands msg;
  for (const protocol::IssuedCommand& c : issued) {
    variational_formation_msgs::FormationCommand m;
    m.step = c.first;
    m.velocity.x = c.second.velocity.x();
    m.velocity.y = c.second.velocity.y();
    m.velocity.z = c.second.velocity.z();
    m.angular_rate.x = c.second.angularRate.x();
    m.angular_rate.y = c.second.angularRate.y();
    m.angular_rate.z = c.second.angularRate.z();
    m.scale = c.second.scale;
    msg.commands.push_back(m);
  }
  msg.header.stamp = stamp;
  return msg;
}

}  // namespace

void MonitorNode::setUpCommands(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  pnh_ = pnh;
  // The formation's limits (doc/manoeuvres.md): beyond them a command is saturated and warned.
  protocol::CommandLimits limits;
  limits.maxSpeed = optionalParam(pnh, "max_speed", 2.0);
  limits.maxTurnRate = optionalParam(pnh, "max_turn_rate", 1.0);
  limits.minScale = optionalParam(pnh, "min_scale", 0.5);
  limits.maxScale = optionalParam(pnh, "max_scale", 2.0);
  desk_ = std::make_unique<protocol::CommandDesk>(scenario_, limits);
  std::istringstream names(optionalParam<std::string>(pnh, "commanders", ""));
  for (std::string name; names >> name;) commanders_.push_back(participantName(nh, name));
  commandPub_ = nh.advertise<variational_formation_msgs::FormationCommands>("command", 10, /*latch=*/true);
  velocityCommandSub_ = nh.subscribe<geometry_msgs::Twist>(
      "cmd_vel", 100,
      boost::function<void(const ros::MessageEvent<geometry_msgs::Twist const>&)>(
          [this](const ros::MessageEvent<geometry_msgs::Twist const>& e) { onVelocityCommand(e); }));
  scaleCommandSub_ = nh.subscribe<std_msgs::Float64>(
      "scale", 100,
      boost::function<void(const ros::MessageEvent<std_msgs::Float64 const>&)>(
          [this](const ros::MessageEvent<std_msgs::Float64 const>& e) { onScaleCommand(e); }));
}

bool MonitorNode::commanderAllowed(const std::string& sender, const char* topic) {
  if (commanders_.empty()) return true;
  for (const std::string& c : commanders_) {
    if (c == sender) return true;
  }
  refuseCommand(topic, sender, "the sender is not in ~commanders");
  return false;
}

void MonitorNode::refuseCommand(const char* topic, const std::string& sender, const std::string& why) {
  ++commandsRefused_;
  ROS_WARN_THROTTLE(1.0, "monitor: dropped a command on %s from %s: %s; %ld dropped so far", topic, sender.c_str(),
                    why.c_str(), commandsRefused_);
}

void MonitorNode::warnCommand(const char* topic, const std::string& sender, const std::string& note) const {
  if (note.empty()) return;
  ROS_WARN("monitor: a command on %s from %s: %s (%ld saturated so far)", topic, sender.c_str(), note.c_str(),
           desk_->saturated());
}

void MonitorNode::onVelocityCommand(const ros::MessageEvent<geometry_msgs::Twist const>& event) {
  const std::string sender = event.getPublisherName();
  if (ended() || !commanderAllowed(sender, "cmd_vel")) return;
  const geometry_msgs::Twist& t = *event.getConstMessage();
  std::string why, note;
  if (!desk_->offerVelocity({t.linear.x, t.linear.y, t.linear.z}, {t.angular.x, t.angular.y, t.angular.z}, why,
                            &note)) {
    refuseCommand("cmd_vel", sender, why);
    return;
  }
  warnCommand("cmd_vel", sender, note);
  commandOffered();
}

void MonitorNode::onScaleCommand(const ros::MessageEvent<std_msgs::Float64 const>& event) {
  const std::string sender = event.getPublisherName();
  if (ended() || !commanderAllowed(sender, "scale")) return;
  std::string why, note;
  if (!desk_->offerScale(event.getConstMessage()->data, why, &note)) {
    refuseCommand("scale", sender, why);
    return;
  }
  warnCommand("scale", sender, note);
  commandOffered();
}

void MonitorNode::publishCommands() {
  commandPub_.publish(toMessage(desk_->issued(), stampOf(desk_->issued().back().first)));
}

long MonitorNode::issueCommands(long allowedStep) {
  if (desk_->issue(allowedStep)) {
    // Kept before any agent can have it: a monitor that restarts goes on from the whole list.
    std::ostringstream kept;
    CommandSchedule issued;
    for (const protocol::IssuedCommand& c : desk_->issued()) issued.add(c.first, c.second);
    writeCommands(kept, issued);
    pnh_.setParam("commands", kept.str());
    measureUnder(desk_->schedule());
    publishCommands();
    const protocol::IssuedCommand& c = desk_->issued().back();
    ROS_INFO("monitor: command %zu from step %ld: v* (%g, %g, %g) m/s, w* (%g, %g, %g) rad/s, s %g",
             desk_->issued().size(), c.first, c.second.velocity.x(), c.second.velocity.y(), c.second.velocity.z(),
             c.second.angularRate.x(), c.second.angularRate.y(), c.second.angularRate.z(), c.second.scale);
  }
  return commandsIssued();
}

void MonitorNode::resumeCommands(bool resumed) {
  std::string kept;
  if (!resumed) {
    pnh_.deleteParam("commands");  // an earlier run's
  } else if (pnh_.getParam("commands", kept)) {
    try {
      const CommandSchedule issued = parseCommands(kept, pnh_.resolveName("commands"), scenario_);
      desk_->resume(issued.entries());
      measureUnder(desk_->schedule());
      ROS_INFO("monitor: going on with the %zu commands issued before the restart", issued.entries().size());
    } catch (const InvalidInput& e) {
      report(protocol::Failure{std::string("the kept commands cannot be read: ") + e.what()});
      return;
    }
  }
  if (!desk_->issued().empty()) publishCommands();
}

}  // namespace vf
