#include "variational_formation/ros/agent_node.hpp"

#include <algorithm>
#include <functional>

#include <ros/callback_queue.h>

#include "variational_formation/core/validation.hpp"
#include "variational_formation/ros/pacer.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/participants.hpp"
#include "variational_formation/ros/sensing_hub.hpp"
#include "variational_formation/ros/state_batch.hpp"

namespace vf {

namespace {
constexpr double kReportEvery = 5.0;  // seconds between "waiting for ..." lines

}  // namespace

AgentNode::AgentNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh) {
  const int id = requiredParam<int>(pnh, "id");
  const std::string path = requiredParam<std::string>(pnh, "scenario");
  realTimeFactor_ = optionalParam(pnh, "real_time_factor", 0.0);
  monitor_ = participantName(nh, optionalParam<std::string>(pnh, "monitor", "monitor"));
  const Scenario scenario = sharedScenario(path);
  validateRealTimeFactor(realTimeFactor_, scenario.timeStep, "~real_time_factor");
  managers_ = agentManagers(nh, pnh);
  const std::shared_ptr<SensingBoard> board = SensingHub::board(nh, scenario, managers_);
  sharedBoard_ = board != nullptr;
  agent_ = std::make_unique<LockstepAgent>(scenario, id, StartMethod::Variational, board);
  name_ = "agent_" + std::to_string(id);
  // Frames carry the namespace, so that two formations side by side have distinct frames.
  const std::string ns = framePrefix(nh);
  frame_ = ns + name_;
  worldFrame_ = worldFrame(pnh);
  statePub_ = nh.advertise<AgentState>(name_ + "/state", 1000, /*latch=*/true);
  for (int j = 0; j < scenario.agentCount(); ++j) owners_.push_back(agentNodeName(nh, j));
  neighbourHistory_.resize(agent_->neighbourIds().size());
  // Served from the start, so that restarting neighbours can ask; the subscriptions wait for
  // start(), which resumes the agent before any state reaches it.
  recallServer_ = nh.advertiseService(name_ + "/recall", &AgentNode::onRecall, this);
  historyServer_ = nh.advertiseService(name_ + "/history", &AgentNode::onHistory, this);
  for (const std::string& w : scenario.warnings) ROS_WARN("%s: %s", name_.c_str(), w.c_str());
  ROS_INFO("%s: scenario '%s' (%s), %d neighbours, kappa %g, h %g, %ld steps%s, real-time factor %g, monitor %s",
           name_.c_str(), scenario.name.c_str(), path.c_str(), static_cast<int>(agent_->neighbourIds().size()),
           scenario.dampingGain, scenario.timeStep, scenario.steps, scenario.steps == 0 ? " (unbounded)" : "",
           realTimeFactor_, monitor_.c_str());
  if (scenario.safety) {
    ROS_INFO("%s: safety filter on (r %g, sensing radius %g); every agent's state from %s", name_.c_str(),
             scenario.safety->radius, scenario.safety->sensingRadius,
             sharedBoard_ ? "the manager's shared board" : "its own topic");
  }
}

AgentNode::~AgentNode() {
  *alive_ = false;
  Pacer::instance().cancel(reinterpret_cast<uint64_t>(this));
}

std::vector<int> AgentNode::sources() const {
  if (!agent_->board() || sharedBoard_) return agent_->neighbourIds();
  std::vector<int> all;
  for (int j = 0; j < agent_->scenario().agentCount(); ++j) {
    if (j != agent_->id()) all.push_back(j);
  }
  return all;
}

void AgentNode::wakeWhenSensed() {
  if (!sharedBoard_ || wakeStep_ == agent_->step()) return;
  wakeStep_ = agent_->step();
  ros::CallbackQueueInterface* queue = nh_.getCallbackQueue();
  const std::shared_ptr<bool> alive = alive_;
  agent_->board()->whenComplete(agent_->step(), [this, queue, alive] {
    queue->addCallback(boost::make_shared<QueuedCall>([this, alive] {
      if (*alive) tryAdvance();
    }), reinterpret_cast<uint64_t>(this));
  });
}

void AgentNode::drop(const std::string& why) {
  ++dropped_;
  ROS_WARN_THROTTLE(1.0, "%s: dropped %s; %ld dropped so far", name_.c_str(), why.c_str(), dropped_);
}

void AgentNode::onNeighbourState(int neighbour, const ros::MessageEvent<AgentState const>& event) {
  try {
    const AgentState& msg = *event.getConstMessage();
    if (!fromAgent(event, owners_[static_cast<std::size_t>(neighbour)], managers_)) {
      drop("a state on agent_" + std::to_string(neighbour) + "'s topic from " + event.getPublisherName() +
           ", which does not own it");
      return;
    }
    const long sender = static_cast<long>(msg.id) == neighbour ? neighbour : -1;
    const auto receipt = agent_->receive(sender, msg.step, msg.position, msg.previous_position);
    if (receipt == LockstepAgent::Receipt::Accepted) {
      const std::vector<int>& ids = agent_->neighbourIds();
      const auto k = static_cast<std::size_t>(std::find(ids.begin(), ids.end(), neighbour) - ids.begin());
      if (k < ids.size()) neighbourHistory_[k].push_back(event.getConstMessage());
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
  // Once its run is over, an agent keeps that run's final word: a monitor started later (which
  // says that the run is over) does not change it.
  if (exitStatus_ >= 0) return;
  if (!hasProgress_ || p.completed_step >= lastProgress_.completed_step) {
    lastProgress_ = p;
    hasProgress_ = true;
    while (!history_.empty() && history_.front()->step <= p.completed_step) history_.pop_front();
    for (auto& held : neighbourHistory_) {
      while (!held.empty() && held.front()->step <= p.completed_step) held.pop_front();
    }
  }
  if (p.state == RunProgress::FINISHED || p.state == RunProgress::FAILED) {
    // Stay up, idle: a respawning agent that exited would only be restarted.
    if (exitStatus_ < 0) {
      ROS_INFO("%s: the run is over at step %ld (%s); idle until shut down", name_.c_str(), agent_->step(),
               p.state == RunProgress::FINISHED ? "finished" : ("failed: " + p.reason).c_str());
    }
    exitStatus_ = p.state == RunProgress::FINISHED ? 0 : 1;
  } else {
    allowedStep_ = std::max(allowedStep_, static_cast<long>(p.allowed_step));
    commandsCounted_ = p.commands;
    tryAdvance();
  }
}

void AgentNode::tryAdvance() {
  while (exitStatus_ < 0 && failure_.empty() && !agent_->finished() && agent_->step() < allowedStep_ &&
         commandsHeld_ >= commandsCounted_) {
    if (!agent_->ready()) {
      wakeWhenSensed();
      return;
    }
    const ros::WallTime now = ros::WallTime::now();
    if (!started_) {
      started_ = true;
      startedAt_ = now;
      startStep_ = agent_->step();
    }
    if (realTimeFactor_ > 0.0) {
      // Step k + 1 is due (k + 1 - k0) h / r after the start at step k0.
      const double due = (agent_->step() + 1 - startStep_) * agent_->scenario().timeStep / realTimeFactor_;
      const double wait = due - (now - startedAt_).toSec();
      if (wait > Pacer::kGrain) {
        paceFor(wait);
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

void AgentNode::paceFor(double wait) {
  if (pacedStep_ == agent_->step()) return;  // already waiting for this step's release
  pacedStep_ = agent_->step();
  const std::shared_ptr<bool> alive = alive_;
  const auto due = Pacer::Clock::now() + std::chrono::duration_cast<Pacer::Clock::duration>(std::chrono::duration<double>(wait));
  Pacer::instance().at(due, nh_.getCallbackQueue(), reinterpret_cast<uint64_t>(this), [this, alive] {
    if (!*alive) return;
    pacedStep_ = -1;
    tryAdvance();
  });
}

void AgentNode::publish() {
  // Built once and published as a pointer to const: subscribers in the same process (nodelets in
  // one manager) receive this very object, without a copy or serialisation.
  const AgentStatePtr state = boost::make_shared<AgentState>();
  AgentState& msg = *state;
  msg.header.stamp.fromSec(agent_->time());
  msg.header.frame_id = worldFrame_;
  msg.id = static_cast<uint32_t>(agent_->id());
  msg.step = agent_->step();
  msg.time = agent_->time();
  msg.position = agent_->position();
  msg.previous_position = agent_->previousPosition();
  msg.dropped = static_cast<uint32_t>(dropped_);
  msg.constraints_active = static_cast<uint32_t>(agent_->constraintsActive());
  msg.failure = failure_;
  const AgentState::ConstPtr published = state;
  statePub_.publish(published);
  history_.push_back(published);
  if (StateBatch* batch = StateBatch::local()) batch->add(published);  // in an agent_manager

  tf_.sendTransform(frameAt(msg.header, frame_, msg.position));
}

std::string AgentNode::waitingFor() const {
  if (!failure_.empty()) return "the monitor to end the run (" + failure_ + ")";
  if (agent_->finished()) return "the monitor to end the run (last step " + std::to_string(agent_->step()) + " done)";
  if (agent_->step() >= allowedStep_) {
    return allowedStep_ == 0 ? "the monitor " + monitor_ + " to start the run (it waits for every participant)"
                             : "the monitor " + monitor_ + " to allow step " + std::to_string(agent_->step() + 1) +
                                   " (flow control: it or the recorder is behind)";
  }
  if (commandsHeld_ < commandsCounted_) {
    return "command " + std::to_string(commandsHeld_ + 1) + " of " + std::to_string(commandsCounted_) +
           " on the monitor's latched `command`";
  }
  std::string missing;
  for (int j : agent_->neighbourIds()) {
    if (!agent_->holdsNeighbourStep(j)) missing += (missing.empty() ? "" : ", ") + std::string("agent_") + std::to_string(j);
  }
  if (missing.empty()) {  // with safety: every agent's state at the step (doc/distributed.md, "Sensing")
    for (int j : agent_->missingSensed(5)) missing += (missing.empty() ? "" : ", ") + std::string("agent_") + std::to_string(j);
    if (!missing.empty()) missing += " (sensing)";
  }
  return missing.empty() ? "its pacing timer" : "the state at step " + std::to_string(agent_->step()) + " of " + missing;
}

void AgentNode::reportWaiting() {
  if (exitStatus_ >= 0) return;
  const ros::WallTime last = lastStepAt_.isZero() ? lastReportAt_ : std::max(lastStepAt_, lastReportAt_);
  if (secondsSince(last) < kReportEvery) return;
  ROS_INFO("%s: at step %ld, waiting for %s", name_.c_str(), agent_->step(), waitingFor().c_str());
  lastReportAt_ = ros::WallTime::now();
}

void AgentNode::start(const Recovery& recovery) {
  resume(recovery);
  subscribeToFormation(
      nh_, sources(), 1000,
      [this](int j, const ros::MessageEvent<AgentState const>& e) { onNeighbourState(j, e); },
      [this](const ros::MessageEvent<RunProgress const>& e) { onProgress(e); }, subs_, progressSub_);
  commandSub_ = nh_.subscribe<variational_formation::FormationCommands>(
      "command", 10,
      boost::function<void(const ros::MessageEvent<variational_formation::FormationCommands const>&)>(
          [this](const ros::MessageEvent<variational_formation::FormationCommands const>& e) { onCommands(e); }),
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  publish();  // the first state (step 0, or the recovered one), latched
  lastReportAt_ = ros::WallTime::now();
  // Every 2.5 s (a waiting line every 5 s at most), from the process's one PeriodicCall thread:
  // a manager holds up to thousands of agents, and a roscpp timer each would stall it.
  watch_ = PeriodicCall(nh_.getCallbackQueue(), kReportEvery / 2, [this] { reportWaiting(); });
}

int AgentNode::run() {
  start(askHolders());
  while (ros::ok()) ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.1));
  ROS_INFO("%s: done at step %ld, %ld states dropped", name_.c_str(), agent_->step(), dropped_);
  return exitStatus_ < 0 ? 0 : exitStatus_;
}

}  // namespace vf
