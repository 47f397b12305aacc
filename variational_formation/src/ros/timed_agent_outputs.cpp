// What the time-driven agent publishes (TimedAgentNode, timed_agent_node.hpp): its state, pose
// and tf, and to its robot the setpoint and cmd_vel; its diagnostics and dynamic reconfigure.
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/Twist.h>

#include "variational_formation_core/model/validation.hpp"
#include "variational_formation/ros/frames.hpp"
#include "variational_formation/ros/participant_names.hpp"
#include "variational_formation/ros/timed_agent_node.hpp"

namespace vf {

void TimedAgentNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const double t = now();
  const double rate = diagnosedAt_ > 0.0 && t > diagnosedAt_ ? (agent_->step() - diagnosedStep_) / (t - diagnosedAt_) : 0.0;
  diagnosedStep_ = agent_->step();
  diagnosedAt_ = t;
  if (exitStatus_ >= 0 || agent_->finished()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "run over");
  } else if (!running_) {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "waiting for the monitor to start the run");
  } else if (robot_ && !link_->measured()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   odomFrames_->refused() > 0 ? "holding: no odometry in the world frame '" + worldFrame_ + "' yet"
                                              : std::string("holding: no odometry yet"));
  } else if (agent_->holding()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "holding: a neighbour is silent");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "stepping");
  }
  status.add("step", agent_->step());
  status.add("step rate [1/s]", rate);
  status.add("expected step rate [1/s]", rate_ / h_);
  status.add("holding", agent_->holding());
  status.add("held ticks", agent_->heldTicks());
  status.add("states lost (injected)", faults_->lost());
  status.add("states refused (outdated or malformed)", agent_->dropped());
  status.add("states dropped (not from the owner)", dropped_);
  status.add("kappa [1/s]", agent_->dampingGain());
  if (agent_->safety()) {
    status.add("safety: constraints active", agent_->constraintsActive());
    status.add("safety: r [m]", agent_->safety()->settings().radius);
    status.add("safety: max speed [m/s]", agent_->safety()->maxSpeed());
  }
  if (robot_) {
    status.add("kinematics", kinematicsName(link_->settings().kinematics));
    status.add("feedback", feedbackName(link_->settings().feedback));
    status.add("cmd_vel sent", link_->commands());
    status.add("cmd_vel saturated (scaled down to max_speed, max_turn_rate)", link_->saturatedCommands());
    status.add("odometry dropped (malformed)", badOdometry_);
    status.add("odometry refused (not in the world frame)", odomFrames_->refused());
    status.add("robot lag + tick [s]", lagCheck_.lagPlusTick);
    status.add("delay margin [s]", lagCheck_.capped ? -1.0 : lagCheck_.marginSeconds);  // -1: none found
    status.add("lag exceeds the delay margin", lagCheck_.exceeded);
    status.add("the margin bounds the lag (odometry feedback)", lagCheck_.applies);
    if (link_->settings().kinematics == RobotKinematics::Unicycle) status.add("heading [rad]", link_->heading());
    if (link_->saturatedCommands() > 0 && status.level == diagnostic_msgs::DiagnosticStatus::OK) {
      status.mergeSummary(diagnostic_msgs::DiagnosticStatus::WARN, "cmd_vel saturated at the limits");
    }
  }
  for (const TimedAgent::NeighbourStatus& n : agent_->neighbourStatus(t)) {
    const std::string who = "agent_" + std::to_string(n.id);
    status.add(who + " age [s]", n.heard ? n.age : -1.0);
    status.add(who + " accepted", n.accepted);
    status.add(who + " dropped", n.dropped);
  }
}

void TimedAgentNode::onReconfigure(variational_formation::TimedAgentConfig& config, uint32_t) {
  config.kappa = applyDampingGain(config.kappa, "~kappa");
}

void TimedAgentNode::onFormationParameters(const ros::MessageEvent<dynamic_reconfigure::Config const>& event) {
  if (!fromOwner(event, monitor_)) {
    drop("formation parameters from " + event.getPublisherName() + ", which is not the monitor " + monitor_);
    return;
  }
  for (const dynamic_reconfigure::DoubleParameter& p : event.getConstMessage()->doubles) {
    if (p.name != "kappa" || p.value == agent_->dampingGain()) continue;
    auto config = variational_formation::TimedAgentConfig::__getDefault__();
    config.kappa = applyDampingGain(p.value, "the formation's kappa");
    reconfigure_->updateConfig(config);  // this agent's server reports it too (dynparam get)
  }
}

double TimedAgentNode::applyDampingGain(double kappa, const std::string& field) {
  if (kappa == agent_->dampingGain()) return kappa;
  if (const auto refusal = refuseDampingGain(h_, kappa, agent_->dampingGain(), field)) {
    ROS_WARN("%s: %s", name_.c_str(), refusal->c_str());
  } else {
    agent_->setDampingGain(kappa);
    ROS_INFO("%s: kappa set to %g from step %ld on (%s)", name_.c_str(), kappa, agent_->step() + 1, field.c_str());
  }
  return agent_->dampingGain();
}

void TimedAgentNode::publish() {
  AgentState msg;
  msg.header.stamp = ros::Time::now();  // ROS time, as robots and tf consumers expect (msg.time: simulated)
  msg.header.frame_id = worldFrame_;
  msg.id = static_cast<uint32_t>(agent_->id());
  msg.step = agent_->step();
  msg.time = agent_->step() * h_;
  msg.position = agent_->position();
  msg.previous_position = agent_->previousPosition();
  msg.dropped = static_cast<uint32_t>(dropped_ + agent_->dropped());
  msg.constraints_active = static_cast<uint32_t>(agent_->constraintsActive());
  msg.foreign_constraints_active = static_cast<uint32_t>(agent_->foreignConstraintsActive());
  statePub_.publish(msg);
  lastPublishAt_ = ros::WallTime::now();

  geometry_msgs::PoseStamped pose;
  pose.header = msg.header;
  pose.pose.position.x = msg.position[0];
  pose.pose.position.y = msg.position[1];
  pose.pose.position.z = msg.position.size() > 2 ? msg.position[2] : 0.0;
  pose.pose.orientation.w = 1.0;
  posePub_.publish(pose);

  tf_.sendTransform(frameAt(msg.header, frame_, msg.position));

  if (robot_) setpointPub_.publish(pose);
}

}  // namespace vf
