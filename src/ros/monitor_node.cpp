#include "variational_formation/ros/monitor_node.hpp"

#include <fstream>
#include <limits>

#include <ros/callback_queue.h>
#include <rosgraph_msgs/Clock.h>

#include "variational_formation/core/number_checks.hpp"
#include "variational_formation/core/run_outcome.hpp"
#include "variational_formation/core/scenario.hpp"
#include "variational_formation/ros/markers.hpp"
#include "variational_formation/ros/output_files.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/participants.hpp"

namespace vf {

MonitorNode::MonitorNode(ros::NodeHandle& nh, ros::NodeHandle& pnh, bool timed) : nh_(nh) {
  path_ = requiredParam<std::string>(pnh, "scenario");
  trailLength_ = optionalParam(pnh, "trail_length", 100);
  window_ = optionalParam(pnh, "window", 100);
  markerEvery_ = optionalParam(pnh, "marker_every", 1);
  if (markerEvery_ < 1) throw InvalidInput("~marker_every: must be >= 1, got " + std::to_string(markerEvery_));
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
  const int n = scenario_.agentCount();
  trails_.resize(static_cast<std::size_t>(n));
  if (!resultFile_.empty()) {
    createParentDirectory(resultFile_, "~result_file");
    announceReplacedResult(resultFile_);
    std::ofstream probe(resultFile_);
    if (!probe) throw InvalidInput("~result_file: cannot write '" + resultFile_ + "'");
    probe << "result: running\n";
  }
  // Latched: a viewer or recorder that connects late still gets the newest step.
  statusPub_ = nh.advertise<FormationStatus>("status", 1000, true);
  markersPub_ = nh.advertise<visualization_msgs::MarkerArray>("markers", 1000, true);
  progressPub_ = nh.advertise<RunProgress>("progress", 10, true);
  if (publishClock_) clockPub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  // A manager's agents come in its batches (one message per step), the others on their own topics.
  batches_ = batchSources(nh, managers_, n);
  std::vector<bool> batched(static_cast<std::size_t>(n), false);
  for (std::size_t m = 0; m < batches_.size(); ++m) {
    for (int id : batches_[m].ids) batched[static_cast<std::size_t>(id)] = true;
    subs_.push_back(nh.subscribe<variational_formation::AgentStates>(
        batches_[m].manager + "/states", static_cast<uint32_t>(2 * window_ + 10),
        boost::function<void(const ros::MessageEvent<variational_formation::AgentStates const>&)>(
            [this, m](const ros::MessageEvent<variational_formation::AgentStates const>& e) { onBatch(m, e); }),
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
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
}

void MonitorNode::announce(const std::string& recorder) const {
  ROS_INFO("monitor: scenario '%s' (%s), %d agents, %zu edges, %ld steps, window %ld, recorder %s%s",
           scenario_.name.c_str(), path_.c_str(), scenario_.agentCount(), measure().formation().edges().size(),
           scenario_.steps, window_, recording_ ? recorder.c_str() : "none",
           waitForViewer_ ? ", waits for a viewer" : "");
}

void MonitorNode::onAgentTopic(int agent, const ros::MessageEvent<AgentState const>& event) {
  const AgentState& msg = *event.getConstMessage();
  if (!fromAgent(event, agents_[static_cast<std::size_t>(agent)].node, managers_)) {
    drop(agent, "from " + event.getPublisherName() + ", which does not own it");
  } else if (static_cast<int>(msg.id) != agent) {
    drop(agent, "with id " + std::to_string(msg.id));
  } else if (admit(agent, msg, event.getPublisherName())) {
    afterAccepted();
  }
}

void MonitorNode::onBatch(std::size_t source, const ros::MessageEvent<variational_formation::AgentStates const>& event) {
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
    accepted = admit(static_cast<int>(msg.id), msg, event.getPublisherName()) || accepted;
    if (ended()) return;
  }
  if (accepted) afterAccepted();
}

bool MonitorNode::admit(int agent, const AgentState& msg, const std::string& publisher) {
  if (!msg.failure.empty()) {
    finish(RunProgress::FAILED, agents_[static_cast<std::size_t>(agent)].node + ": " + msg.failure);
    return false;
  }
  return offer(agent, msg, publisher);
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

MonitorNode::Published MonitorNode::publishSnapshot(const FormationSnapshot& s, const ros::Time& stamp,
                                                    double dataAge, bool noetherHolds) {
  const ros::WallTime now = ros::WallTime::now();
  if (s.metrics.step == 0) firstStepAt_ = now;
  lastCompletedAt_ = now;
  for (std::size_t i = 0; i < trails_.size(); ++i) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    p.head(s.positions.rows()) = s.positions.col(static_cast<Eigen::Index>(i));
    trails_[i].push_back(p);
    if (static_cast<int>(trails_[i].size()) > trailLength_) trails_[i].pop_front();
  }
  Published out;
  FormationStatus& status = out.first;
  status = toStatusMessage(s);
  status.header.stamp = stamp;
  status.dropped = static_cast<uint32_t>(dropped_);
  status.max_data_age = dataAge;
  if (!noetherHolds) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    status.linear_momentum_predicted.x = status.linear_momentum_predicted.y = status.linear_momentum_predicted.z = nan;
    status.angular_momentum_predicted.x = status.angular_momentum_predicted.y = nan;
    status.angular_momentum_predicted.z = nan;
  }
  statusPub_.publish(status);
  // Never backwards: with several formations on one master, the one furthest ahead sets it.
  if (publishClock_ && (!ros::Time::isSimTime() || stamp >= ros::Time::now())) {
    rosgraph_msgs::Clock clock;
    clock.clock = stamp;
    clockPub_.publish(clock);
  }
  // Markers cost O(n x trail length) per step: built only when someone takes them (the recorder,
  // a viewer), every marker_every steps, and always at the first and last step so that the
  // latched one is right. The trails above still get every step.
  const long last = scenario_.steps;
  const bool edge = s.metrics.step == 0 || (last > 0 && s.metrics.step == last);
  if (edge || (s.metrics.step % markerEvery_ == 0 && (recording_ || markersPub_.getNumSubscribers() > 0))) {
    out.second = makeMarkers(s, measure().formation(), trails_);
    for (auto& m : out.second.markers) m.header.stamp = stamp;
    markersPub_.publish(out.second);
  }
  convergedStep_ = s.converged ? s.convergedStep : -1;
  finalError_ = s.metrics.maxDistanceError;
  if (s.converged && reportedConvergence_ != s.convergedStep) {
    ROS_INFO("monitor: congruent with the desired shape since step %ld (t = %.3f s)", s.convergedStep,
             s.convergedStep * scenario_.timeStep);
    reportedConvergence_ = s.convergedStep;
  } else if (!s.converged && reportedConvergence_ >= 0) {
    ROS_INFO("monitor: left the desired shape at step %ld", s.metrics.step);
    reportedConvergence_ = -2;
  }
  return out;
}

void MonitorNode::publishProgress(const RunProgress& progress) {
  progress_ = progress;
  progress_.header.stamp.fromSec(std::max(0L, static_cast<long>(progress.completed_step)) * scenario_.timeStep);
  progressPub_.publish(progress_);
}

bool MonitorNode::checkAlive(Participant& p, const std::string& what, double timeout) {
  if (!p.seen) return true;  // not started yet: the waiting line says so
  // An agent in a nodelet manager has no node of its own: its host is the manager.
  const Liveness l = nodeLiveness(p.host.empty() ? p.node : p.host);
  if (l == Liveness::Alive) {
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
  finish(RunProgress::FAILED, what + " " + p.node + " ended before the run was over (" + describe(l) + host + ")");
  return false;
}

void MonitorNode::reportWaiting(const std::string& line) {
  if (secondsSince(lastReportAt_) < 5.0) return;  // a line every 5 s at most
  ROS_INFO("monitor: %s", line.c_str());
  lastReportAt_ = ros::WallTime::now();
}

void MonitorNode::writeResult(const std::string& result, const std::string& reason) const {
  if (resultFile_.empty()) return;
  std::ofstream f(resultFile_);
  std::string quoted;
  for (char c : reason) quoted += c == '"' ? std::string("\\\"") : std::string(1, c);
  const FormationOutcome formation = formationOutcome(convergedStep_, finalError_, scenario_.timeStep);
  f << "result: " << result << "\nscenario: " << scenario_.name << "\nsteps: " << scenario_.steps
    << "\ncompleted_step: " << completedStep() << "\nconverged_step: " << convergedStep_ << "\nformation: \""
    << formation.line << "\"\nfinal_max_distance_error: " << finalError_ << "\ndropped: " << dropped_
    << "\nreason: \"" << quoted << "\"\n";
  if (!f) ROS_ERROR("monitor: cannot write the result file %s", resultFile_.c_str());
}

void MonitorNode::finish(uint8_t state, std::string reason) {
  if (ended()) return;
  const long last = completedStep();
  const double h = scenario_.timeStep;
  const FormationOutcome formation = formationOutcome(convergedStep_, finalError_, h);
  const RunVerdict verdict = finishedRunVerdict(scenario_, formation);
  if (state == RunProgress::FINISHED) {
    const double seconds = (ros::WallTime::now() - firstStepAt_).toSec();
    ROS_INFO("monitor: %ld steps in %.3f s: %.0f steps/s, real-time factor %.1f at h = %g; %s; %ld dropped", last,
             seconds, last / seconds, last * h / seconds, h, formation.line.c_str(), dropped_);
  }
  if (state == RunProgress::FINISHED && !verdict.succeeded) {
    state = RunProgress::FAILED;  // the scenario asked for a formation that did not form
    reason = verdict.reason;
  }
  if (state == RunProgress::FINISHED) {
    writeResult("succeeded", "");
    // The last line says whether the formation formed: a run that never formed is no plain success.
    ROS_INFO("monitor: run succeeded; formation %s (%s)", formation.line.c_str(),
             resultFile_.empty() ? "no result file" : resultFile_.c_str());
    exitStatus_ = 0;
  } else {
    writeResult("failed", reason);
    ROS_ERROR("monitor: run failed at step %ld: %s", last, reason.c_str());
    exitStatus_ = 1;
  }
  progress_.state = state;
  progress_.reason = reason;
  progressPub_.publish(progress_);
}

int MonitorNode::run() {
  begin();
  lastReportAt_ = ros::WallTime::now();
  progressPub_.publish(progress_);
  watchTimer_ = nh_.createWallTimer(ros::WallDuration(0.5), [this](const ros::WallTimerEvent&) {
    if (!ended()) watch();
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
