#include "variational_formation/ros/monitor_node.hpp"

#include <fstream>

#include <ros/callback_queue.h>
#include <rosgraph_msgs/Clock.h>

#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation/ros/markers.hpp"
#include "variational_formation/ros/output_files.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/frames.hpp"
#include "variational_formation/ros/liveness.hpp"
#include "variational_formation/ros/participant_names.hpp"

namespace vf {

MonitorNode::MonitorNode(ros::NodeHandle& nh, ros::NodeHandle& pnh, bool timed) : nh_(nh) {
  path_ = requiredParam<std::string>(pnh, "scenario");
  worldFrame_ = worldFrame(pnh);
  trailLength_ = optionalParam(pnh, "trail_length", 100);
  window_ = optionalParam(pnh, "window", 100);
  recorderParam_ = optionalParam<std::string>(pnh, "recorder", "");
  resultFile_ = outputPath(nh, optionalParam<std::string>(pnh, "result_file", ""));
  waitForViewer_ = optionalParam(pnh, "wait_for_viewer", false);
  respawnTimeout_ = optionalParam(pnh, "respawn_timeout", 0.0);
  managers_ = agentManagers(nh, pnh);
  if (trailLength_ < 2) throw InvalidInput("~trail_length: must be >= 2");
  if (window_ < 1) throw InvalidInput("~window: must be >= 1, got " + std::to_string(window_));
  if (!(respawnTimeout_ >= 0.0)) throw InvalidInput("~respawn_timeout: must be >= 0");
  if (timed && !recorderParam_.empty()) {
    throw InvalidInput("~recorder: recording is for lockstep mode; timed mode has none");
  }
  publishClock_ = optionalParam(pnh, "publish_clock", false);
  if (publishClock_ && timed) {
    throw InvalidInput("~publish_clock: lockstep only; timed agents run on ROS time, which a clock must not replace");
  }
  recording_ = !recorderParam_.empty();
  scenario_ = loadScenario(path_);
  markerEvery_ = markerEvery(optionalParam(pnh, "marker_every", 0), scenario_.timeStep);
  const int n = scenario_.agentCount();
  trails_ = Trails(n, trailLength_);
  allMarkersEvery_ = allMarkersEvery(trails_.stride(), scenario_.timeStep);
  if (!resultFile_.empty()) {
    createParentDirectory(resultFile_, "~result_file");
    announceReplacedResult(resultFile_);
    std::ofstream probe(resultFile_);
    if (!probe) throw InvalidInput("~result_file: cannot write '" + resultFile_ + "'");
    probe << "result: running\n";
  }
  // Latched: a viewer or recorder that connects late still gets the newest step.
  statusPub_ = nh.advertise<FormationStatus>("status", 1000, true);
  // A viewer is a subscriber of the markers other than the recorder (which reads them too).
  const std::string recorder = recording_ ? participantName(nh, recorderParam_) : "";
  markersPub_ = nh.advertise<visualization_msgs::MarkerArray>(
      "markers", 1000,
      [this, recorder](const ros::SingleSubscriberPublisher& s) { viewers_ += s.getSubscriberName() != recorder; },
      [this, recorder](const ros::SingleSubscriberPublisher& s) {
        if (s.getSubscriberName() != recorder && viewers_ > 0) --viewers_;
      },
      ros::VoidConstPtr(), true);
  progressPub_ = nh.advertise<RunProgress>("progress", 10, true);
  if (publishClock_) clockPub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  // A manager's agents come in its batches (one message per step), the others on their own topics.
  batches_ = batchSources(nh, managers_, n);
  std::vector<bool> batched(static_cast<std::size_t>(n), false);
  for (std::size_t m = 0; m < batches_.size(); ++m) {
    for (int id : batches_[m].ids) batched[static_cast<std::size_t>(id)] = true;
    // As deep as the agents' own topics together: a batch may hold a single state.
    const uint32_t depth = static_cast<uint32_t>((2 * window_ + 10) * static_cast<long>(batches_[m].ids.size()));
    subs_.push_back(subscribeToBatches(
        nh, batches_[m].manager + "/states", depth,
        [this, m](const ros::MessageEvent<variational_formation_msgs::AgentStates const>& e) { onBatch(m, e); }));
  }
  for (int i = 0; i < n; ++i) {
    agents_.push_back({agentNodeName(nh, i), false, ros::WallTime(), ""});
    if (batched[static_cast<std::size_t>(i)]) continue;
    subs_.push_back(nh.subscribe<AgentState>(
        "agent_" + std::to_string(i) + "/state", static_cast<uint32_t>(2 * window_ + 10),
        boost::function<void(const ros::MessageEvent<AgentState const>&)>(
            [this, i](const ros::MessageEvent<AgentState const>& e) { onAgentTopic(i, e); }),
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
  }
  progress_.state = RunProgress::WAITING;
  progress_.completed_step = -1;
  progress_.allowed_step = 0;
  progress_.converged_step = -1;
  setUpCommands(nh, pnh);
  setUpGoals(nh, pnh);
  setUpSafety(pnh, timed);
  setUpRobots(nh, pnh, timed);
  setUpParameters(nh, timed);
}

void MonitorNode::announce(const std::string& recorder) const {
  ROS_INFO("monitor: scenario '%s' (%s), %d agents, %zu edges, %ld steps, window %ld, recorder %s%s",
           scenario_.name.c_str(), path_.c_str(), scenario_.agentCount(), measure().formation().edges().size(),
           scenario_.steps, window_, recording_ ? recorder.c_str() : "none",
           waitForViewer_ ? ", waits for a viewer" : "");
}

void MonitorNode::onAgentTopic(int agent, const ros::MessageEvent<AgentState const>& event) {
  const AgentState::ConstPtr& held = event.getConstMessage();
  const AgentState& msg = *held;
  if (!fromAgent(event, agents_[static_cast<std::size_t>(agent)].node, managers_)) {
    drop(agent, "from " + event.getPublisherName() + ", which does not own it");
  } else if (static_cast<int>(msg.id) != agent) {
    drop(agent, "with id " + std::to_string(msg.id));
  } else if (admit(agent, held, event.getPublisherName())) {
    afterAccepted();
  }
}

void MonitorNode::onBatch(std::size_t source, const ros::MessageEvent<variational_formation_msgs::AgentStates const>& event) {
  const BatchSource& from = batches_[source];
  if (!fromOwner(event, from.manager)) {
    ++dropped_;
    ROS_WARN_THROTTLE(1.0, "monitor: dropped a batch of states on %s/states from %s, which is not that manager",
                      from.manager.c_str(), event.getPublisherName().c_str());
    return;
  }
  bool accepted = false;
  for (const AgentState& msg : event.getConstMessage()->states) {
    if (from.ids.count(static_cast<int>(msg.id)) == 0) {
      ++dropped_;
      ROS_WARN_THROTTLE(1.0, "monitor: dropped a state of agent %u in a batch of %s, which does not hold that agent",
                        msg.id, from.manager.c_str());
      continue;
    }
    // Held by pointer into the batch (which it keeps alive), not copied.
    accepted = admit(static_cast<int>(msg.id), AgentState::ConstPtr(event.getConstMessage(), &msg),
                     event.getPublisherName()) || accepted;
    if (ended()) return;
  }
  if (accepted) afterAccepted();
}

bool MonitorNode::admit(int agent, const AgentState::ConstPtr& msg, const std::string& publisher) {
  const std::string& node = agents_[static_cast<std::size_t>(agent)].node;
  if (!msg->failure.empty()) {
    report(protocol::Failure{node + ": " + msg->failure});
    return false;
  }
  if (!finiteState(msg->position, msg->previous_position)) {
    // Its owner diverged (an agent reports that itself, with its last good state): the run is over.
    report(protocol::Failure{node + ": step " + std::to_string(msg->step) + " is not finite (the run diverged)"});
    return false;
  }
  if (!offer(agent, msg, publisher)) return false;
  noteSafety(agent, *msg);
  return true;
}

void MonitorNode::heard(int agent, const std::string& publisher) {
  Participant& owner = agents_[static_cast<std::size_t>(agent)];
  owner.seen = true;
  owner.host = publisher;
  owner.goneSince = ros::WallTime();
}

void MonitorNode::drop(int agent, const std::string& why) {
  ++dropped_;
  ROS_WARN_THROTTLE(1.0, "monitor: dropped a state on agent_%d's topic %s; %ld dropped so far", agent, why.c_str(),
                    dropped_);
}

void MonitorNode::publishProgress(const RunProgress& progress) {
  progress_ = progress;
  progress_.header.stamp = stampOf(progress.completed_step);
  progressPub_.publish(progress_);
}

bool MonitorNode::checkAlive(Participant& p, const std::string& what, double timeout) {
  if (!p.seen) return true;  // not started yet: the waiting line says so
  // An agent in a nodelet manager has no node of its own: its host is the manager.
  const Liveness l = nodeLiveness(p.host.empty() ? p.node : p.host);
  if (l == Liveness::Alive || l == Liveness::Busy) {
    p.goneSince = ros::WallTime();
    return true;
  }
  const std::string host = p.host.empty() || p.host == p.node ? "" : ", its host " + p.host;
  if (p.goneSince.isZero()) {
    p.goneSince = ros::WallTime::now();
    if (timeout > 0.0) {
      ROS_WARN("monitor: %s %s is gone (%s%s); waiting up to %.1f s for it to come back", what.c_str(), p.node.c_str(),
               describe(l), host.c_str(), timeout);
    }
  }
  if (secondsSince(p.goneSince) < timeout) return true;
  report(protocol::Failure{what + " " + p.node + " ended before the run was over (" + describe(l) + host + ")"});
  return false;
}

void MonitorNode::reportWaiting(const std::string& line) {
  if (secondsSince(lastReportAt_) < 5.0) return;  // a line every 5 s at most
  ROS_INFO("monitor: %s", line.c_str());
  lastReportAt_ = ros::WallTime::now();
}

int MonitorNode::run() {
  begin();
  lastReportAt_ = ros::WallTime::now();
  progress_.header.stamp = stampOf(progress_.completed_step);
  progressPub_.publish(progress_);
  watchTimer_ = nh_.createWallTimer(ros::WallDuration(0.5), [this](const ros::WallTimerEvent&) {
    if (!ended()) watch();
    if (publishClock_) publishClock();  // one held back while steps came faster than kClockPeriod
  });
  auto* queue = ros::getGlobalCallbackQueue();
  while (ros::ok() && !ended()) queue->callAvailable(ros::WallDuration(0.1));
  if (!ended()) {
    // Shut down from outside (Ctrl-C, roslaunch): an unbounded run is stopped, a bounded one failed.
    if (scenario_.steps == 0) {
      writeResult("stopped", "stopped at step " + std::to_string(completedStep()));
      ROS_INFO("monitor: run stopped at step %ld", completedStep());
      return 0;
    }
    const std::string reason = "interrupted before the last step, waiting for " + waitingFor();
    writeResult("failed", reason);
    ROS_ERROR("monitor: run failed at step %ld: %s", completedStep(), reason.c_str());
    return 1;
  }
  // Stay up, idle: with respawn, a monitor that exited would only be restarted. formation.launch
  // ends with end_of_run, which exits on the final progress.
  while (ros::ok()) queue->callAvailable(ros::WallDuration(0.1));
  return exitStatus_;
}

std::unique_ptr<MonitorNode> makeMonitor(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  const std::string mode = optionalParam<std::string>(pnh, "mode", "lockstep");
  if (mode == "lockstep") return std::make_unique<LockstepMonitor>(nh, pnh);
  if (mode == "timed") return std::make_unique<TimedMonitor>(nh, pnh);
  throw InvalidInput("~mode: must be lockstep or timed, got '" + mode + "'");
}

}  // namespace vf
