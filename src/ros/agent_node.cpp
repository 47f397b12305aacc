#include "variational_formation/ros/agent_node.hpp"

#include <geometry_msgs/TransformStamped.h>
#include <ros/callback_queue.h>

#include "variational_formation/core/validation.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/participants.hpp"

namespace vf {

namespace {
constexpr double kReportEvery = 5.0;  // seconds between "waiting for ..." lines
}

AgentNode::AgentNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh) {
  const int id = requiredParam<int>(pnh, "id");
  const std::string path = requiredParam<std::string>(pnh, "scenario");
  realTimeFactor_ = optionalParam(pnh, "real_time_factor", 0.0);
  monitor_ = participantName(nh, optionalParam<std::string>(pnh, "monitor", "monitor"));
  const Scenario scenario = loadScenario(path);
  validateRealTimeFactor(realTimeFactor_, scenario.timeStep, "~real_time_factor");
  agent_ = std::make_unique<LockstepAgent>(scenario, id);
  name_ = "agent_" + std::to_string(id);
  // Frames carry the namespace, so that two formations side by side have distinct frames.
  const std::string ns = nh.getNamespace() == "/" ? "" : nh.getNamespace().substr(1) + "/";
  frame_ = ns + name_;
  statePub_ = nh.advertise<AgentState>(name_ + "/state", 1000, /*latch=*/true);
  for (int j : agent_->neighbourIds()) {
    neighbourOwners_.push_back(agentNodeName(nh, j));
    subs_.push_back(nh.subscribe<AgentState>(
        "agent_" + std::to_string(j) + "/state", 1000,
        boost::function<void(const ros::MessageEvent<AgentState const>&)>(
            [this, j](const ros::MessageEvent<AgentState const>& e) { onNeighbourState(j, e); }),
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
  }
  progressSub_ = nh.subscribe<RunProgress>(
      "progress", 10,
      boost::function<void(const ros::MessageEvent<RunProgress const>&)>(
          [this](const ros::MessageEvent<RunProgress const>& e) { onProgress(e); }),
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  for (const std::string& w : scenario.warnings) ROS_WARN("%s: %s", name_.c_str(), w.c_str());
  ROS_INFO("%s: scenario '%s' (%s), %d neighbours, kappa %g, h %g, %ld steps%s, real-time factor %g, monitor %s",
           name_.c_str(), scenario.name.c_str(), path.c_str(), static_cast<int>(agent_->neighbourIds().size()),
           scenario.dampingGain, scenario.timeStep, scenario.steps, scenario.steps == 0 ? " (unbounded)" : "",
           realTimeFactor_, monitor_.c_str());
}

void AgentNode::drop(const std::string& why) {
  ++dropped_;
  ROS_WARN_THROTTLE(1.0, "%s: dropped %s; %ld dropped so far", name_.c_str(), why.c_str(), dropped_);
}

void AgentNode::onNeighbourState(int neighbour, const ros::MessageEvent<AgentState const>& event) {
  try {
    const AgentState& msg = *event.getConstMessage();
    std::size_t k = 0;
    while (agent_->neighbourIds()[k] != neighbour) ++k;
    if (!fromOwner(event, neighbourOwners_[k])) {
      drop("a state on agent_" + std::to_string(neighbour) + "'s topic from " + event.getPublisherName() +
           ", which does not own it");
      return;
    }
    const long sender = static_cast<long>(msg.id) == neighbour ? neighbour : -1;
    const auto receipt = agent_->receive(sender, msg.step, msg.position, msg.previous_position);
    if (receipt == LockstepAgent::Receipt::Accepted) {
      tryAdvance();
    } else if (receipt != LockstepAgent::Receipt::Duplicate) {
      drop("a state from agent_" + std::to_string(neighbour) + " (step " + std::to_string(msg.step) +
           "): " + LockstepAgent::describe(receipt));
    }
  } catch (const std::exception& e) {
    drop(std::string("a state: ") + e.what());
  }
}

void AgentNode::onProgress(const ros::MessageEvent<RunProgress const>& event) {
  if (!fromOwner(event, monitor_)) {
    drop("a progress message from " + event.getPublisherName() + ", which is not the monitor " + monitor_);
    return;
  }
  const RunProgress& p = *event.getConstMessage();
  if (p.state == RunProgress::FINISHED) {
    ROS_INFO("%s: the monitor says the run is finished at step %ld; exiting", name_.c_str(), agent_->step());
    exitStatus_ = 0;
  } else if (p.state == RunProgress::FAILED) {
    ROS_INFO("%s: the monitor says the run failed (%s); exiting", name_.c_str(), p.reason.c_str());
    exitStatus_ = 1;
  } else {
    allowedStep_ = std::max(allowedStep_, static_cast<long>(p.allowed_step));
    tryAdvance();
  }
}

void AgentNode::tryAdvance() {
  while (exitStatus_ < 0 && failure_.empty() && !agent_->finished() && agent_->step() < allowedStep_ && agent_->ready()) {
    const ros::WallTime now = ros::WallTime::now();
    if (!started_) {
      started_ = true;
      startedAt_ = now;
    }
    if (realTimeFactor_ > 0.0) {
      // Step k + 1 is due (k + 1) h / r after the start.
      const double due = (agent_->step() + 1) * agent_->scenario().timeStep / realTimeFactor_;
      const double wait = due - (now - startedAt_).toSec();
      if (wait > 0.0) {
        paceTimer_ = nh_.createWallTimer(ros::WallDuration(wait), [this](const ros::WallTimerEvent&) { tryAdvance(); },
                                         /*oneshot=*/true);
        return;
      }
    }
    agent_->advance();
    if (!agent_->finite()) {
      // Never publish a non-finite state: report the divergence with the last good one, and let
      // the monitor end the run (doc/distributed.md).
      failure_ = "step " + std::to_string(agent_->step()) + " is not finite (the run diverged)";
      ROS_ERROR("%s: %s; ending the run", name_.c_str(), failure_.c_str());
      agent_->undo();
      publish();
      return;
    }
    publish();
    lastStepAt_ = now;
  }
}

void AgentNode::publish() {
  AgentState msg;
  msg.header.stamp.fromSec(agent_->time());
  msg.header.frame_id = "world";
  msg.id = static_cast<uint32_t>(agent_->id());
  msg.step = agent_->step();
  msg.time = agent_->time();
  msg.position = agent_->position();
  msg.previous_position = agent_->previousPosition();
  msg.dropped = static_cast<uint32_t>(dropped_);
  msg.failure = failure_;
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

std::string AgentNode::waitingFor() const {
  if (!failure_.empty()) return "the monitor to end the run (" + failure_ + ")";
  if (agent_->finished()) return "the monitor to end the run (last step " + std::to_string(agent_->step()) + " done)";
  if (agent_->step() >= allowedStep_) {
    return allowedStep_ == 0 ? "the monitor " + monitor_ + " to start the run (it waits for every participant)"
                             : "the monitor " + monitor_ + " to allow step " + std::to_string(agent_->step() + 1) +
                                   " (flow control: it or the recorder is behind)";
  }
  std::string missing;
  for (int j : agent_->neighbourIds()) {
    if (!agent_->holdsNeighbourStep(j)) missing += (missing.empty() ? "" : ", ") + std::string("agent_") + std::to_string(j);
  }
  return missing.empty() ? "its pacing timer" : "the state at step " + std::to_string(agent_->step()) + " of " + missing;
}

void AgentNode::reportWaiting() {
  const ros::WallTime last = lastStepAt_.isZero() ? lastReportAt_ : std::max(lastStepAt_, lastReportAt_);
  if (secondsSince(last) < kReportEvery) return;
  ROS_INFO("%s: at step %ld, waiting for %s", name_.c_str(), agent_->step(), waitingFor().c_str());
  lastReportAt_ = ros::WallTime::now();
}

int AgentNode::run() {
  publish();  // step 0, latched: whoever connects later still gets it
  lastReportAt_ = ros::WallTime::now();
  watchTimer_ = nh_.createWallTimer(ros::WallDuration(1.0), [this](const ros::WallTimerEvent&) { reportWaiting(); });
  while (ros::ok() && exitStatus_ < 0) ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.1));
  ROS_INFO("%s: done at step %ld, %ld states dropped", name_.c_str(), agent_->step(), dropped_);
  return exitStatus_ < 0 ? 0 : exitStatus_;
}

}  // namespace vf
