#include "variational_formation/ros/agent_node.hpp"

#include <algorithm>
#include <functional>

#include <ros/callback_queue.h>

#include "variational_formation_core/model/validation.hpp"
#include "variational_formation/ros/pacer.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/formation_subscriptions.hpp"
#include "variational_formation/ros/frames.hpp"
#include "variational_formation/ros/liveness.hpp"
#include "variational_formation/ros/participant_names.hpp"
#include "variational_formation/ros/shared_scenario.hpp"
#include "variational_formation/ros/progress_message.hpp"
#include "variational_formation/ros/sensing_hub.hpp"
#include "variational_formation/ros/state_batch.hpp"

namespace vf {

namespace {
constexpr double kReportEvery = 5.0;  // seconds between "waiting for ..." lines
constexpr double kMonitorWait = 2.0;  // seconds a resumed agent in a manager waits for the monitor to connect
}  // namespace

AgentNode::AgentNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh) {
  const int id = requiredParam<int>(pnh, "id");
  const std::string path = requiredParam<std::string>(pnh, "scenario");
  realTimeFactor_ = optionalParam(pnh, "real_time_factor", 0.0);
  monitor_ = participantName(nh, optionalParam<std::string>(pnh, "monitor", "monitor"));
  // One scenario and formation for all the agents of the process, not a copy each.
  const std::shared_ptr<const Scenario> shared = sharedScenarioObject(path);
  const Scenario& scenario = *shared;
  validateRealTimeFactor(realTimeFactor_, scenario.timeStep, "~real_time_factor");
  managers_ = agentManagers(nh, pnh);
  const std::shared_ptr<SensingBoard> board = SensingHub::board(nh, scenario, managers_);
  sharedBoard_ = board != nullptr;
  formation_ = sharedFormation(shared);
  LockstepAgent lockstep(shared, formation_, id, StartMethod::Variational, board);
  avoidOtherFormations(nh, pnh, lockstep);
  protocol_ = std::make_unique<Protocol>(
      std::move(lockstep),
      [this](const LockstepAgent& a, const std::string& failure) { return makeState(a, failure); }, realTimeFactor_,
      [] { return ros::WallTime::now().toSec(); }, Pacer::kGrain);
  name_ = "agent_" + std::to_string(id);
  // Frames carry the namespace, so that two formations side by side have distinct frames.
  const std::string ns = framePrefix(nh);
  frame_ = ns + name_;
  worldFrame_ = worldFrame(pnh);
  exchange_ = LocalStates::of(nh);
  if (exchange_ && !exchange_->hosts(id)) exchange_ = nullptr;
  if (exchange_) LocalStates::place(id, nh.getCallbackQueue());
  advertiseState(nh);
  for (int j : sources()) owners_[j] = agentNodeName(nh, j);  // only whose topics it reads
  // Served from the start, so that restarting neighbours can ask; the subscriptions wait for
  // start(), which resumes the agent before any state reaches it.
  recallServer_ = nh.advertiseService(name_ + "/recall", &AgentNode::onRecall, this);
  historyServer_ = nh.advertiseService(name_ + "/history", &AgentNode::onHistory, this);
  for (const std::string& w : scenario.warnings) ROS_WARN("%s: %s", name_.c_str(), w.c_str());
  ROS_INFO("%s: scenario '%s' (%s), %d neighbours, kappa %g, h %g, %ld steps%s, real-time factor %g, monitor %s",
           name_.c_str(), scenario.name.c_str(), path.c_str(), static_cast<int>(agent().neighbourIds().size()),
           scenario.dampingGain, scenario.timeStep, scenario.steps, scenario.steps == 0 ? " (unbounded)" : "",
           realTimeFactor_, monitor_.c_str());
  if (scenario.safety) {
    ROS_INFO("%s: safety filter on (r %g, sensing radius %g); every agent's state from %s", name_.c_str(),
             scenario.safety->radius, scenario.safety->sensingRadius,
             sharedBoard_ ? "the manager's shared board" : "its own topic");
  }
}

void AgentNode::advertiseState(ros::NodeHandle& nh) {
  if (!exchange_) {
    statePub_ = nh.advertise<AgentState>(name_ + "/state", 1000, /*latch=*/true);
    return;
  }
  audience_ = std::make_unique<TopicAudience<AgentState::ConstPtr>>(ros::this_node::getName());
  // Connections are reported on this agent's queue, where it publishes: no lock is needed.
  const std::shared_ptr<bool> alive = alive_;
  ros::AdvertiseOptions options = ros::AdvertiseOptions::create<AgentState>(
      name_ + "/state", 1000,
      [this, alive](const ros::SingleSubscriberPublisher& s) {
        if (!*alive) return;
        if (const AgentState::ConstPtr newest = audience_->connected(s.getSubscriberName())) s.publish(*newest);
        if (s.getSubscriberName() == monitor_) monitorConnected();  // a monitor that reads the agents' topics
      },
      ros::SubscriberStatusCallback(), ros::VoidConstPtr(), nullptr);
  options.latch = true;  // once live (TopicAudience): the latch hands a new subscriber the newest
  statePub_ = nh.advertise(options);
}

AgentNode::~AgentNode() {
  if (exchange_) exchange_->stopListening(reinterpret_cast<std::uintptr_t>(this));
  *alive_ = false;
  inboxReader_->node = nullptr;
  Pacer::instance().cancel(reinterpret_cast<uint64_t>(this));
}

void AgentNode::drop(const std::string& why) {
  ++dropped_;
  ROS_WARN_THROTTLE(1.0, "%s: dropped %s; %ld dropped so far", name_.c_str(), why.c_str(), dropped_);
}

void AgentNode::carryOut(const Protocol::Ready& ready) {
  if (!ready.failed.empty()) ROS_ERROR("%s: %s; ending the run", name_.c_str(), ready.failed.c_str());
  for (const AgentState::ConstPtr& state : ready.publish) publish(state);
  if (!ready.dropped.empty()) drop(ready.dropped);
  if (!ready.note.empty()) ROS_INFO("%s: %s", name_.c_str(), ready.note.c_str());
  if (!ready.over.empty()) ROS_INFO("%s: %s", name_.c_str(), ready.over.c_str());
  if (ready.resumedAt >= 0) ROS_INFO("%s: resumed at step %ld, the holders' newer state of mine", name_.c_str(), ready.resumedAt);
  if (ready.recallAgain) recallAgain();
  if (!ready.askNeighbourHistories.empty()) askNeighbourHistories(ready.askNeighbourHistories);
  if (ready.wakeWhenSensed) wakeWhenSensed();
  if (ready.wakeAfter > 0.0) paceFor(ready.wakeAfter);
}

void AgentNode::paceFor(double wait) {
  if (pacedStep_ == agent().step()) return;  // already waiting for this step's release
  pacedStep_ = agent().step();
  const std::shared_ptr<bool> alive = alive_;
  const auto due = Pacer::Clock::now() + std::chrono::duration_cast<Pacer::Clock::duration>(std::chrono::duration<double>(wait));
  Pacer::instance().at(due, nh_.getCallbackQueue(), reinterpret_cast<uint64_t>(this), [this, alive] {
    if (!*alive) return;
    pacedStep_ = -1;
    carryOut(protocol_->step(Protocol::Wake{}));
  });
}

void AgentNode::onNeighbourState(int neighbour, const ros::MessageEvent<AgentState const>& event) {
  // From this process, a local neighbour's state reached the agent through the exchange already.
  if (exchange_ && exchange_->hosts(neighbour) && event.getPublisherName() == ros::this_node::getName()) return;
  if (!fromAgent(event, owners_.at(neighbour), managers_)) {
    drop("a state on agent_" + std::to_string(neighbour) + "'s topic from " + event.getPublisherName() +
         ", which does not own it");
    return;
  }
  carryOut(protocol_->step(Protocol::StateArrived{neighbour, event.getConstMessage()}));
}

void AgentNode::onProgress(const ros::MessageEvent<RunProgress const>& event) {
  if (!fromOwner(event, monitor_)) {
    drop("a progress message from " + event.getPublisherName() + ", which is not the monitor " + monitor_);
    return;
  }
  if (awaitMonitor_) {  // resumed: the progress waits until the monitor is connected
    heldProgress_ = event;
    progressHeld_ = true;
    return;
  }
  const RunProgress& p = *event.getConstMessage();
  carryOut(protocol_->step(Protocol::ProgressArrived{agentProgressOf(p), p}));
}

AgentState::ConstPtr AgentNode::makeState(const LockstepAgent& a, const std::string& failure) const {
  // Built once and published as a pointer to const: subscribers in the same process (nodelets in
  // one manager) receive this very object, without a copy or serialisation (ReusedMessages).
  const AgentStatePtr state = made_.next();
  AgentState& msg = *state;
  msg.header.stamp.fromSec(a.time());
  msg.header.frame_id = worldFrame_;
  msg.id = static_cast<uint32_t>(a.id());
  msg.step = a.step();
  msg.time = a.time();
  msg.position = a.position();
  msg.previous_position = a.previousPosition();
  msg.dropped = static_cast<uint32_t>(dropped_);
  msg.constraints_active = static_cast<uint32_t>(a.constraintsActive());
  msg.foreign_constraints_active = static_cast<uint32_t>(a.foreignConstraintsActive());
  msg.failure = failure;
  return state;
}

void AgentNode::publish(const AgentState::ConstPtr& state) {
  if (!exchange_) {
    statePub_.publish(state);
  } else {
    exchange_->deliver(agent().id(), state);
    if (audience_->published(state)) statePub_.publish(state);
  }
  if (StateBatch* batch = StateBatch::local()) batch->add(state);  // in an agent_manager
  tf_.send(state->header, frame_, state->position);
}

void AgentNode::reportWaiting() {
  if (awaitMonitor_ && secondsSince(awaitSince_) >= kMonitorWait) {
    ROS_WARN("%s: resumed at step %ld, and the monitor %s has not connected to this manager's states within "
             "%.0f s; going on without it", name_.c_str(), agent().step(), monitor_.c_str(), kMonitorWait);
    monitorConnected();
  }
  if (protocol_->exitStatus() >= 0) return;
  // Seen to move since the last look (every kReportEvery / 2): it is not waiting.
  if (agent().step() != stepSeen_) {
    stepSeen_ = agent().step();
    stepSeenAt_ = ros::WallTime::now();
  }
  if (secondsSince(std::max(stepSeenAt_, lastReportAt_)) < kReportEvery) return;
  ROS_INFO("%s: at step %ld, waiting for %s", name_.c_str(), agent().step(), protocol_->waitingFor(monitor_).c_str());
  lastReportAt_ = ros::WallTime::now();
}

void AgentNode::listenLocally() {
  if (!exchange_) return;
  ros::CallbackQueueInterface* queue = nh_.getCallbackQueue();
  const std::shared_ptr<bool> alive = alive_;
  for (int j : sources()) {
    if (!exchange_->hosts(j)) continue;
    // A neighbour on this agent's thread: into the inbox, read right after the callback that
    // published it (depth first: the state is still in the cache). One on another thread: a
    // call on this agent's queue. Either way per neighbour, so its states stay in order.
    // (The neighbour's queue is placed before it publishes anything that reaches this handler.)
    exchange_->listen(j, reinterpret_cast<std::uintptr_t>(this),
                      [this, queue, alive](int source, const AgentState::ConstPtr& state) {
                        if (LocalStates::queueOf(source) == queue && AgentThreads::serves(queue)) {
                          inbox_.emplace_back(source, state);
                          if (!inboxRead_) {
                            inboxRead_ = true;
                            AgentThreads::soon(inboxReader_);
                          }
                          return;
                        }
                        queueCall(queue, [this, alive, source, state] {
                          if (*alive) carryOut(protocol_->step(Protocol::StateArrived{source, state}));
                        }, reinterpret_cast<uint64_t>(this));
                      });
  }
}

void AgentNode::readInbox() {
  inboxRead_ = false;
  // Only the thread's lane calls this, never from within itself: one Ready serves every state
  // read here, and the inbox is read by index (a state handed over meanwhile goes to its end
  // and is read in this loop too), both keeping their memory.
  for (std::size_t k = 0; k < inbox_.size(); ++k) {
    const std::pair<int, AgentState::ConstPtr> arrived = std::move(inbox_[k]);
    protocol_->step(Protocol::StateArrived{arrived.first, arrived.second}, ready_);
    carryOut(ready_);
  }
  inbox_.clear();
  ready_.clear();  // holds no state past its use
}

void AgentNode::start(const Recovery& recovery) {
  resume(recovery);
  StateBatch* batch = StateBatch::local();
  if (agent().step() > 0 && batch && batch->ids().count(agent().id()) > 0) {
    // Before the progress can arrive: start() runs on the agent's queue, as every callback below.
    awaitMonitor_ = true;
    awaitSince_ = ros::WallTime::now();
    const std::shared_ptr<bool> alive = alive_;
    if (batch->connectedOrLater(monitor_, nh_.getCallbackQueue(), [this, alive] {
          if (*alive) monitorConnected();
        })) {
      awaitMonitor_ = false;
    }
  }
  subscribeToFormation(
      nh_, sources(), 1000,
      [this](int j, const ros::MessageEvent<AgentState const>& e) { onNeighbourState(j, e); },
      [this](const ros::MessageEvent<RunProgress const>& e) { onProgress(e); }, subs_, progressSub_);
  listenLocally();
  commandSub_ = nh_.subscribe<variational_formation_msgs::FormationCommands>(
      "command", 10,
      boost::function<void(const ros::MessageEvent<variational_formation_msgs::FormationCommands const>&)>(
          [this](const ros::MessageEvent<variational_formation_msgs::FormationCommands const>& e) { onCommands(e); }),
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  carryOut(protocol_->start());  // the first state (step 0, or the recovered one), latched
  lastReportAt_ = ros::WallTime::now();
  stepSeen_ = agent().step();
  stepSeenAt_ = lastReportAt_;
  // Every 2.5 s (a waiting line every 5 s at most), from the process's one PeriodicCall thread:
  // a manager holds up to thousands of agents, and a roscpp timer each would stall it.
  watch_ = PeriodicCall(nh_.getCallbackQueue(), kReportEvery / 2, [this] { reportWaiting(); });
}

int AgentNode::run() {
  start(askHolders());
  while (ros::ok()) ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.1));
  ROS_INFO("%s: done at step %ld, %ld states dropped", name_.c_str(), agent().step(), dropped_);
  return protocol_->exitStatus() < 0 ? 0 : protocol_->exitStatus();
}

}  // namespace vf
