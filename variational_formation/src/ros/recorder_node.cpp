#include "variational_formation/ros/recorder_node.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <ros/callback_queue.h>

#include "variational_formation_core/protocol/recovery.hpp"
#include "variational_formation/ros/output_files.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/frames.hpp"
#include "variational_formation/ros/markers.hpp"
#include "variational_formation/ros/participant_names.hpp"
#include "variational_formation/ros/progress_message.hpp"
#include "variational_formation/ros/service_call.hpp"

namespace vf {

namespace {
// Queues far longer than the monitor's window lets the agents run ahead, and each agent's newest
// states kept to compare repeats with; the monitor checks its ~window against both at start-up.
const protocol::RecorderBuffers kBuffers;
const uint32_t kQueue = static_cast<uint32_t>(kBuffers.queue);

}  // namespace

RecorderNode::RecorderNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh) {
  scenario_ = loadScenario(requiredParam<std::string>(pnh, "scenario"));
  const Scenario& scenario = scenario_;
  path_ = outputPath(nh, requiredParam<std::string>(pnh, "bag"));
  monitor_ = participantName(nh, optionalParam<std::string>(pnh, "monitor", "monitor"));
  managers_ = agentManagers(nh, pnh);
  markerEvery_ = markerEvery(optionalParam(pnh, "marker_every", 0), scenario.timeStep);
  lastStep_ = scenario.steps;
  timeStep_ = scenario.timeStep;
  const int n = scenario.agentCount();
  protocol_ = std::make_unique<Protocol>(
      n, kBuffers.keptSteps, lastStep_, [this](long step) { return needsMarkers(step); },
      [](const FormationStatus::ConstPtr& status) { return static_cast<long>(status->commands); });
  const double splitMb = optionalParam(pnh, "split_size", 256.0);
  const double maxMb = optionalParam(pnh, "max_size", 1024.0);
  if (!(splitMb >= 0.0 && splitMb < 1e9)) throw InvalidInput("~split_size: must be in [0, 1e9) MB, got " + std::to_string(splitMb));
  if (!(maxMb >= 0.0 && maxMb < 1e9)) throw InvalidInput("~max_size: must be in [0, 1e9) MB, got " + std::to_string(maxMb));
  const std::string compression = optionalParam<std::string>(pnh, "compression", "lz4");
  if (compression != "lz4" && compression != "none") {
    throw InvalidInput("~compression: must be lz4 or none, got '" + compression + "'");
  }
  compression_ = compression == "lz4" ? BagWriter::Compression::Lz4 : BagWriter::Compression::None;
  splitBytes_ = splitMb * 1e6;
  maxBytes_ = maxMb * 1e6;
  createParentDirectory(path_, "~bag");
  replaceEarlierBag(path_);
  openPart();
  const std::string prefix = framePrefix(nh);
  statusTopic_ = BagWriter::Topic(nh.resolveName("status"));
  markersTopic_ = BagWriter::Topic(nh.resolveName("markers"));
  // A manager's agents come in its batches (one message per step), the others on their own topics.
  batches_ = batchSources(nh, managers_, n);
  std::vector<bool> batched(static_cast<std::size_t>(n), false);
  for (std::size_t m = 0; m < batches_.size(); ++m) {
    for (int id : batches_[m].ids) batched[static_cast<std::size_t>(id)] = true;
    subs_.push_back(subscribeToBatches(
        nh, batches_[m].manager + "/states", kQueue,
        [this, m](const ros::MessageEvent<variational_formation_msgs::AgentStates const>& e) { onBatch(m, e); }));
  }
  for (int i = 0; i < n; ++i) {
    owners_.push_back(agentNodeName(nh, i));
    stateTopics_.emplace_back(nh.resolveName("agent_" + std::to_string(i) + "/state"));
    frameIds_.push_back(prefix + "agent_" + std::to_string(i));
    if (batched[static_cast<std::size_t>(i)]) continue;
    subs_.push_back(nh.subscribe<AgentState>(
        "agent_" + std::to_string(i) + "/state", kQueue,
        boost::function<void(const ros::MessageEvent<AgentState const>&)>(
            [this, i](const ros::MessageEvent<AgentState const>& e) { onState(i, e); }),
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
  }
  subs_.push_back(nh.subscribe<FormationStatus>(
      "status", kQueue,
      boost::function<void(const ros::MessageEvent<FormationStatus const>&)>(
          [this](const ros::MessageEvent<FormationStatus const>& e) { onStatus(e); }),
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
  subs_.push_back(nh.subscribe<RawMarkers>(
      "markers", kQueue,
      boost::function<void(const ros::MessageEvent<RawMarkers const>&)>(
          [this](const ros::MessageEvent<RawMarkers const>& e) { onMarkers(e); }),
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
  subs_.push_back(nh.subscribe<RunProgress>(
      "progress", 10,
      boost::function<void(const ros::MessageEvent<RunProgress const>&)>(
          [this](const ros::MessageEvent<RunProgress const>& e) { onMonitorProgress(e); })));
  setUpCommands(nh, pnh);
  progressPub_ = pnh.advertise<RunProgress>("progress", 10, true);
  ROS_INFO("recorder: writing %s (%d agents, %ld steps), monitor %s, %s, %s", path_.c_str(), n, lastStep_,
           monitor_.c_str(), maxMb > 0 ? ("at most " + std::to_string(static_cast<long>(maxMb)) + " MB").c_str() : "no size limit",
           splitMb > 0 ? ("files of " + std::to_string(static_cast<long>(splitMb)) + " MB").c_str() : "one file");
}

void RecorderNode::onState(int agent, const ros::MessageEvent<AgentState const>& event) {
  const AgentState::ConstPtr msg = event.getConstMessage();
  if (!fromAgent(event, owners_[static_cast<std::size_t>(agent)], managers_) || static_cast<int>(msg->id) != agent) {
    ++dropped_;
    ROS_WARN_THROTTLE(1.0, "recorder: dropped a state on agent_%d's topic from %s; %ld dropped so far", agent,
                      event.getPublisherName().c_str(), dropped_);
    return;
  }
  record(agent, msg);
}

void RecorderNode::onBatch(std::size_t source, const ros::MessageEvent<variational_formation_msgs::AgentStates const>& event) {
  const BatchSource& from = batches_[source];
  const bool owner = fromOwner(event, from.manager);
  for (const AgentState& msg : event.getConstMessage()->states) {
    if (!owner || from.ids.count(static_cast<int>(msg.id)) == 0) {
      ++dropped_;
      ROS_WARN_THROTTLE(1.0, "recorder: dropped a state of agent %u in a batch on %s/states from %s; %ld dropped so far",
                        msg.id, from.manager.c_str(), event.getPublisherName().c_str(), dropped_);
      continue;
    }
    // Held by pointer into the batch (which it keeps alive), not copied.
    record(static_cast<int>(msg.id), AgentState::ConstPtr(event.getConstMessage(), &msg));
  }
}

void RecorderNode::catchUp() {
  const Protocol::Ready tick = protocol_->step(Protocol::Tick{ros::WallTime::now().toSec()});
  if (!tick.catchUp) return;
  const std::vector<int>& agents = tick.fetch;
  std::vector<std::string> services;
  for (int i : agents) services.push_back(owners_[static_cast<std::size_t>(i)] + "/history");
  // Ask the agents, and the monitor, which keeps what it accepted until this recorder confirms
  // it (an agent that died again no longer holds its states).
  std::vector<RecallHistory> calls(2 * agents.size());
  for (std::size_t k = 0; k < agents.size(); ++k) {
    calls[k].request.id = agents[k];
    services.push_back(monitor_ + "/history");
    calls[agents.size() + k].request.id = agents[k];
  }
  const std::vector<bool> answered = callAllWithTimeout(services, calls, 2.0);
  Protocol::HistoriesArrived held{0.0, {}};
  for (std::size_t c = 0; c < calls.size(); ++c) {
    if (!answered[c]) continue;
    held.answers.emplace_back(agents[c % agents.size()], sharedStates(calls[c].response.states));
  }
  held.now = ros::WallTime::now().toSec();
  carryOut(protocol_->step(held));
}

void RecorderNode::record(int agent, const AgentState::ConstPtr& msg) {
  carryOut(protocol_->step(Protocol::StateArrived{agent, msg}));
}

void RecorderNode::carryOut(const Protocol::Ready& r) {
  if (!r.dropped.empty()) {
    ++dropped_;
    ROS_WARN_THROTTLE(1.0, "recorder: dropped %s; %ld dropped so far", r.dropped.c_str(), dropped_);
  }
  if (!r.failed.empty()) {
    // It tells the monitor, which ends the run as failed, naming the reason.
    progressPub_.publish(progressMessage(*r.report));
    ROS_ERROR("recorder: %s", r.failed.c_str());
    close(r.close);
    exitStatus_ = r.exit;
    return;
  }
  for (const Protocol::Write& w : r.write) writeStep(w);
  // Unless writing failed meanwhile; a finished recording is closed before the monitor hears it.
  if (r.report && protocol_->progress().state != protocol::Progress::State::Failed) {
    if (!r.close.empty()) close(r.close);
    progressPub_.publish(progressMessage(*r.report));
  }
  if (!r.close.empty()) close(r.close);
  if (r.exit >= 0) exitStatus_ = r.exit;
}

RunProgress RecorderNode::progressMessage(const protocol::Progress& p) const {
  RunProgress m;
  m.state = toMessage(p).state;
  m.completed_step = p.completedStep;
  m.reason = p.reason;
  if (p.completedStep >= 0) m.header.stamp.fromSec(static_cast<double>(p.completedStep) * timeStep_);
  return m;
}

bool RecorderNode::needsMarkers(long step) const {
  return step % markerEvery_ == 0 || (lastStep_ > 0 && step == lastStep_);
}

void RecorderNode::onStatus(const ros::MessageEvent<FormationStatus const>& event) {
  if (!fromOwner(event, monitor_)) return;
  const FormationStatus::ConstPtr msg = event.getConstMessage();
  carryOut(protocol_->step(Protocol::StatusArrived{static_cast<long>(msg->step), msg}));
}

ros::Time RecorderNode::markersStamp(const RawMarkers& msg) {
  // A MarkerArray is serialised as its number of markers, then each marker, which begins with its
  // header: seq, then stamp (seconds, nanoseconds), all little-endian uint32.
  std::uint32_t count = 0, seconds = 0, nanoseconds = 0;
  if (msg.bytes.size() < 16) return ros::TIME_MIN;
  std::memcpy(&count, msg.bytes.data(), 4);
  if (count == 0) return ros::TIME_MIN;
  std::memcpy(&seconds, msg.bytes.data() + 8, 4);
  std::memcpy(&nanoseconds, msg.bytes.data() + 12, 4);
  return ros::Time(seconds, nanoseconds);
}

void RecorderNode::onMarkers(const ros::MessageEvent<RawMarkers const>& event) {
  if (!fromOwner(event, monitor_)) return;
  const auto msg = event.getConstMessage();
  const long step = protocol::stepOfStamp(markersStamp(*msg).toSec(), timeStep_);
  carryOut(protocol_->step(Protocol::MarkersArrived{step, msg}));
}

void RecorderNode::onMonitorProgress(const ros::MessageEvent<RunProgress const>& event) {
  if (!fromOwner(event, monitor_)) return;
  carryOut(protocol_->step(Protocol::MonitorProgress{agentProgressOf(*event.getConstMessage()).progress}));
}

void RecorderNode::fail(const std::string& reason) { carryOut(protocol_->step(Protocol::Failure{reason})); }

int RecorderNode::run() {
  auto* queue = ros::getGlobalCallbackQueue();
  protocol_->startClock(ros::WallTime::now().toSec());
  catchUpTimer_ = nh_.createWallTimer(ros::WallDuration(0.5), [this](const ros::WallTimerEvent&) { catchUp(); });
  while (ros::ok() && exitStatus_ < 0) queue->callAvailable(ros::WallDuration(0.1));
  close("interrupted");
  return exitStatus_ < 0 ? 0 : exitStatus_;
}

}  // namespace vf
