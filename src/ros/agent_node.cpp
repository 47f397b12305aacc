#include "variational_formation/ros/agent_node.hpp"

#include <geometry_msgs/TransformStamped.h>
#include <ros/callback_queue.h>
#include <tf2_msgs/TFMessage.h>

#include "variational_formation/ros/parameters.hpp"

namespace vf {

AgentNode::AgentNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  const int id = requiredParam<int>(pnh, "id");
  const std::string path = requiredParam<std::string>(pnh, "scenario");
  realTimeFactor_ = optionalParam(pnh, "real_time_factor", 0.0);
  extraSubscribers_ = optionalParam(pnh, "extra_subscribers", 1);
  tfSubscribers_ = optionalParam(pnh, "tf_subscribers", 0);
  if (!(realTimeFactor_ >= 0.0)) throw InvalidInput("~real_time_factor: must be >= 0 (0 = as fast as possible)");
  if (extraSubscribers_ < 0 || tfSubscribers_ < 0) throw InvalidInput("~extra_subscribers/~tf_subscribers: must be >= 0");
  const Scenario scenario = loadScenario(path);
  agent_ = std::make_unique<LockstepAgent>(scenario, id);
  frame_ = "agent_" + std::to_string(id);
  statePub_ = nh.advertise<AgentState>(frame_ + "/state", 1000, /*latch=*/true);
  tfProbe_ = nh.advertise<tf2_msgs::TFMessage>("/tf", 100);
  for (int j : agent_->neighbourIds()) {
    subs_.push_back(nh.subscribe("agent_" + std::to_string(j) + "/state", 1000,
                                             boost::function<void(const AgentState::ConstPtr&)>(
                                                 [this, j](const AgentState::ConstPtr& m) { onState(j, m); }),
                                 ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
  }
  for (const std::string& w : scenario.warnings) ROS_WARN("%s: %s", frame_.c_str(), w.c_str());
  ROS_INFO("%s: scenario '%s' (%s), %d neighbours, kappa %g, h %g, %ld steps%s, real-time factor %g",
           frame_.c_str(), scenario.name.c_str(), path.c_str(),
           static_cast<int>(agent_->neighbourIds().size()), scenario.dampingGain, scenario.timeStep,
           scenario.steps, scenario.steps == 0 ? " (unbounded)" : "", realTimeFactor_);
}

void AgentNode::onState(int expectedSender, const AgentState::ConstPtr& msg) {
  try {
    const long sender = static_cast<long>(msg->id) == expectedSender ? expectedSender : -1;
    const auto receipt = agent_->receive(sender, msg->step, msg->position, msg->previous_position);
    if (receipt == LockstepAgent::Receipt::Accepted || receipt == LockstepAgent::Receipt::Duplicate) return;
    ++dropped_;
    ROS_WARN_THROTTLE(1.0, "%s: dropped a state from agent %u (step %ld): %s; %ld dropped so far",
                      frame_.c_str(), msg->id, static_cast<long>(msg->step),
                      LockstepAgent::describe(receipt).c_str(), dropped_);
  } catch (const std::exception& e) {
    ++dropped_;
    ROS_WARN_THROTTLE(1.0, "%s: dropped a state: %s", frame_.c_str(), e.what());
  }
}

void AgentNode::publish() {
  AgentState msg;
  msg.header.stamp = ros::Time::now();
  msg.header.frame_id = "world";
  msg.id = static_cast<uint32_t>(agent_->id());
  msg.step = agent_->step();
  msg.time = agent_->time();
  msg.position = agent_->position();
  msg.previous_position = agent_->previousPosition();
  statePub_.publish(msg);

  geometry_msgs::TransformStamped t;
  t.header = msg.header;
  t.child_frame_id = frame_;
  t.transform.translation.x = msg.position[0];
  t.transform.translation.y = msg.position[1];
  t.transform.translation.z = msg.position.size() > 2 ? msg.position[2] : 0.0;
  t.transform.rotation.w = 1.0;
  tf_.sendTransform(t);
}

void AgentNode::waitForSubscribers() {
  // Every subscriber must be connected before step 0: then no step is missed by the monitor,
  // the recorder or a neighbour (the latched state covers a connection that comes later).
  const unsigned required = static_cast<unsigned>(agent_->neighbourIds().size() + extraSubscribers_);
  ros::WallTime lastLog = ros::WallTime::now();
  while (ros::ok() && (statePub_.getNumSubscribers() < required ||
                       tfProbe_.getNumSubscribers() < static_cast<unsigned>(tfSubscribers_))) {
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.005));
    if ((ros::WallTime::now() - lastLog).toSec() > 5.0) {
      ROS_INFO("%s: waiting for subscribers (%u of %u on the state, %u of %d on /tf)", frame_.c_str(),
               statePub_.getNumSubscribers(), required, tfProbe_.getNumSubscribers(), tfSubscribers_);
      lastLog = ros::WallTime::now();
    }
  }
}

void AgentNode::run() {
  waitForSubscribers();
  const ros::WallTime start = ros::WallTime::now();
  publish();
  auto* queue = ros::getGlobalCallbackQueue();
  while (ros::ok() && !agent_->finished()) {
    // Block only while a neighbour's state is missing: callAvailable returns as soon as one
    // arrives, so a long timeout costs no latency and spares idle wake-ups (50 agents on 2 cores).
    queue->callAvailable(agent_->ready() ? ros::WallDuration(0.0) : ros::WallDuration(0.1));
    if (!agent_->ready()) continue;
    if (realTimeFactor_ > 0.0) {
      const double due = (agent_->step() + 1) * agent_->scenario().timeStep / realTimeFactor_;
      const double wait = due - (ros::WallTime::now() - start).toSec();
      if (wait > 0.0) ros::WallDuration(wait).sleep();
    }
    agent_->advance();
    publish();
  }
  // Linger so that the last (latched) state reaches neighbours that are one step behind.
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(1.0);
  while (ros::ok() && ros::WallTime::now() < end) queue->callAvailable(ros::WallDuration(0.01));
  ROS_INFO("%s: done at step %ld in %.3f s, %ld malformed messages dropped", frame_.c_str(), agent_->step(),
           (ros::WallTime::now() - start).toSec() - 1.0, dropped_);
}

}  // namespace vf
