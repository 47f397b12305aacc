#include "variational_formation/ros/monitor_node.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

#include <ros/callback_queue.h>
#include <ros/master.h>
#include <rosgraph_msgs/Clock.h>

#include "variational_formation/core/number_checks.hpp"
#include "variational_formation/core/protocol/recovery.hpp"
#include "variational_formation/core/run_outcome.hpp"
#include "variational_formation/ros/markers.hpp"
#include "variational_formation/ros/output_files.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/participants.hpp"
#include "variational_formation/ros/service_call.hpp"

namespace vf {

namespace {
constexpr double kReportEvery = 5.0;   // seconds between "waiting for ..." lines
constexpr double kCheckAfter = 1.0;    // a step stalled this long makes the monitor look for dead participants

std::string agentList(const std::vector<int>& ids) {
  std::string s;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (k == 8) return s + " and " + std::to_string(ids.size() - k) + " more";
    s += (k ? ", " : "") + std::string("agent_") + std::to_string(ids[k]);
  }
  return s;
}
}  // namespace

MonitorNode::MonitorNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh) {
  const std::string path = requiredParam<std::string>(pnh, "scenario");
  trailLength_ = optionalParam(pnh, "trail_length", 100);
  window_ = optionalParam(pnh, "window", 100);
  markerEvery_ = optionalParam(pnh, "marker_every", 1);
  if (markerEvery_ < 1) throw InvalidInput("~marker_every: must be >= 1, got " + std::to_string(markerEvery_));
  const std::string recorder = optionalParam<std::string>(pnh, "recorder", "");
  resultFile_ = outputPath(nh, optionalParam<std::string>(pnh, "result_file", ""));
  waitForViewer_ = optionalParam(pnh, "wait_for_viewer", false);
  respawnTimeout_ = optionalParam(pnh, "respawn_timeout", 0.0);
  managers_ = agentManagers(nh, pnh);
  if (trailLength_ < 2) throw InvalidInput("~trail_length: must be >= 2");
  if (window_ < 1) throw InvalidInput("~window: must be >= 1, got " + std::to_string(window_));
  if (!(respawnTimeout_ >= 0.0)) throw InvalidInput("~respawn_timeout: must be >= 0");
  const std::string mode = optionalParam<std::string>(pnh, "mode", "lockstep");
  if (mode != "lockstep" && mode != "timed") {
    throw InvalidInput("~mode: must be lockstep or timed, got '" + mode + "'");
  }
  timed_ = mode == "timed";
  if (timed_) {
    rate_ = optionalParam(pnh, "real_time_factor", 0.0);
    requireFiniteAbove("~real_time_factor (timed mode: the status period is h / rate)", rate_, 0.0, "");
    if (!recorder.empty()) throw InvalidInput("~recorder: recording is for lockstep mode; timed mode has none");
  }
  publishClock_ = optionalParam(pnh, "publish_clock", false);
  if (publishClock_ && timed_) {
    throw InvalidInput("~publish_clock: lockstep only; timed agents run on ROS time, which a clock must not replace");
  }
  monitor_ = std::make_unique<FormationMonitor>(loadScenario(path));
  const int n = monitor_->formation().agentCount();
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
  for (int i = 0; i < n; ++i) {
    agents_.push_back({agentNodeName(nh, i), false, ros::WallTime(), ""});
    subs_.push_back(nh.subscribe<AgentState>(
        "agent_" + std::to_string(i) + "/state", static_cast<uint32_t>(2 * window_ + 10),
        boost::function<void(const ros::MessageEvent<AgentState const>&)>(
            [this, i](const ros::MessageEvent<AgentState const>& e) { onState(i, e); }),
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
  }
  recording_ = !recorder.empty();
  if (recording_) {
    const std::string disagree = protocol::checkBuffers(window_);
    if (!disagree.empty()) throw InvalidInput(disagree);
    recorder_.node = participantName(nh, recorder);
    recorderSub_ = nh.subscribe<RunProgress>(
        recorder + "/progress", 10,
        boost::function<void(const ros::MessageEvent<RunProgress const>&)>(
            [this](const ros::MessageEvent<RunProgress const>& e) { onRecorderProgress(e); }),
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  }
  newest_.resize(static_cast<std::size_t>(n));
  for (auto& m : newest_) m.step = -1;
  recallServer_ = pnh.advertiseService("recall", &MonitorNode::onRecall, this);
  historyServer_ = pnh.advertiseService("history", &MonitorNode::onHistory, this);
  unrecordedStates_.resize(static_cast<std::size_t>(n));
  progress_.state = RunProgress::WAITING;
  progress_.completed_step = -1;
  progress_.allowed_step = 0;
  progress_.converged_step = -1;
  ROS_INFO("monitor: scenario '%s' (%s), %d agents, %zu edges, %ld steps, window %ld, recorder %s%s",
           monitor_->scenario().name.c_str(), path.c_str(), n, monitor_->formation().edges().size(),
           monitor_->scenario().steps, window_, recording_ ? recorder_.node.c_str() : "none",
           waitForViewer_ ? ", waits for a viewer" : "");
}

void MonitorNode::onState(int agent, const ros::MessageEvent<AgentState const>& event) {
  const AgentState& msg = *event.getConstMessage();
  Participant& owner = agents_[static_cast<std::size_t>(agent)];
  std::string why;
  if (!fromAgent(event, owner.node, managers_)) {
    why = "from " + event.getPublisherName() + ", which does not own it";
  } else if (static_cast<int>(msg.id) != agent) {
    why = "with id " + std::to_string(msg.id);
  } else if (!msg.failure.empty()) {
    finish(RunProgress::FAILED, owner.node + ": " + msg.failure);
    return;
  } else if (timed_) {
    if (acceptTimed(agent, msg, why)) {
      owner.seen = true;
      owner.host = event.getPublisherName();
      owner.goneSince = ros::WallTime();
      return;
    }
  } else {
    try {
      const auto receipt = monitor_->add(agent, msg.step, msg.position, msg.previous_position, acceptUpTo_);
      if (receipt == FormationMonitor::Receipt::Accepted || receipt == FormationMonitor::Receipt::Duplicate) {
        if (msg.step > newest_[static_cast<std::size_t>(agent)].step) newest_[static_cast<std::size_t>(agent)] = msg;
        if (recording_ && receipt == FormationMonitor::Receipt::Accepted) {
          unrecordedStates_[static_cast<std::size_t>(agent)].push_back(msg);
        }
        owner.seen = true;
        owner.host = event.getPublisherName();
        owner.goneSince = ros::WallTime();
        if (receipt == FormationMonitor::Receipt::Accepted) publishCompleted();
        return;
      }
      why = "(step " + std::to_string(msg.step) + "): " + FormationMonitor::describe(receipt);
    } catch (const std::exception& e) {
      why = e.what();
    }
  }
  ++dropped_;
  ROS_WARN_THROTTLE(1.0, "monitor: dropped a state on agent_%d's topic %s; %ld dropped so far", agent, why.c_str(),
                    dropped_);
}

void MonitorNode::onRecorderProgress(const ros::MessageEvent<RunProgress const>& event) {
  if (!fromOwner(event, recorder_.node)) {
    ++dropped_;
    ROS_WARN_THROTTLE(1.0, "monitor: dropped a recorder progress from %s, which is not %s",
                      event.getPublisherName().c_str(), recorder_.node.c_str());
    return;
  }
  const RunProgress& p = *event.getConstMessage();
  recorder_.seen = true;
  recorder_.goneSince = ros::WallTime();
  if (p.state == RunProgress::FAILED) {
    finish(RunProgress::FAILED, "the recorder failed: " + p.reason);
    return;
  }
  recordedStep_ = std::max(recordedStep_, static_cast<long>(p.completed_step));
  while (!unrecorded_.empty() && unrecorded_.front().first.step <= recordedStep_) unrecorded_.pop_front();
  for (auto& states : unrecordedStates_) {
    while (!states.empty() && states.front().step <= recordedStep_) states.pop_front();
  }
  recorderDone_ = p.state == RunProgress::FINISHED;
  updateProgress();
}

void MonitorNode::publishCompleted() {
  const ros::WallTime now = ros::WallTime::now();
  for (const FormationSnapshot& s : monitor_->takeCompleted()) {
    if (s.metrics.step == 0) firstStepAt_ = now;
    lastCompletedAt_ = now;
    for (int i = 0; i < monitor_->formation().agentCount(); ++i) {
      auto& trail = trails_[static_cast<std::size_t>(i)];
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      p.head(s.positions.rows()) = s.positions.col(i);
      trail.push_back(p);
      if (static_cast<int>(trail.size()) > trailLength_) trail.pop_front();
    }
    ros::Time stamp;
    stamp.fromSec(s.metrics.time);  // simulated time t_k
    FormationStatus status = toStatusMessage(s);
    status.header.stamp = stamp;
    status.dropped = static_cast<uint32_t>(dropped_);
    status.max_data_age = dataAge_;
    if (timed_) {
      // Noether's laws are those of one synchronous run; the time-driven agents are not that.
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
    // Markers cost O(n x trail length) per step: built only when someone takes them (the
    // recorder, a viewer), every marker_every steps, and always at the first and last step so
    // that the latched one is right. The trails above still get every step.
    const long last = monitor_->scenario().steps;
    const bool edge = s.metrics.step == 0 || (last > 0 && s.metrics.step == last);
    visualization_msgs::MarkerArray markers;
    if (edge || (s.metrics.step % markerEvery_ == 0 && (recording_ || markersPub_.getNumSubscribers() > 0))) {
      markers = makeMarkers(s, monitor_->formation(), trails_);
      for (auto& m : markers.markers) m.header.stamp = stamp;
      markersPub_.publish(markers);
    }
    if (recording_) unrecorded_.push_back({status, markers});
    convergedStep_ = s.converged ? s.convergedStep : -1;
    finalError_ = s.metrics.maxDistanceError;
    congruentSinceAt_[s.metrics.step] = convergedStep_;
    if (s.converged && reportedConvergence_ != s.convergedStep) {
      ROS_INFO("monitor: congruent with the desired shape since step %ld (t = %.3f s)", s.convergedStep,
               s.convergedStep * monitor_->scenario().timeStep);
      reportedConvergence_ = s.convergedStep;
    } else if (!s.converged && reportedConvergence_ >= 0) {
      ROS_INFO("monitor: left the desired shape at step %ld", s.metrics.step);
      reportedConvergence_ = -2;
    }
  }
  updateProgress();
}

void MonitorNode::updateProgress() {
  if (exitStatus_ >= 0) return;
  const long last = monitor_->scenario().steps;
  const long completed = completedStep();
  const long base = recording_ ? std::min(completed, recordedStep_) : completed;
  RunProgress next = progress_;
  next.completed_step = base;
  if (progress_.state == RunProgress::WAITING) {
    // Start by identity: every agent's step 0 is here (completed), the recorder holds step 0,
    // and, if asked, a viewer listens to the markers.
    const bool viewer = !waitForViewer_ || markersPub_.getNumSubscribers() > 0;
    if (base < 0 || !viewer) return;
    next.state = RunProgress::RUNNING;
    startedAt_ = ros::WallTime::now();
  }
  next.allowed_step = base + window_;
  if (last > 0) next.allowed_step = std::min<long>(next.allowed_step, last);
  if (last > 0 && completed >= last && (!recording_ || recorderDone_)) {
    finish(RunProgress::FINISHED, "");
    return;
  }
  // Publish on every change of state, and otherwise every quarter window: agents never wait
  // for a step the window already allows.
  const long every = std::max<long>(1, window_ / 4);
  // ... and whenever the agents may already wait at the allowed step (nothing more is coming).
  const bool agentsMayWait = completed >= progress_.allowed_step;
  if (next.state != progress_.state || next.allowed_step >= progress_.allowed_step + every ||
      (next.allowed_step > progress_.allowed_step && (next.allowed_step == last || agentsMayWait))) {
    next.header.stamp.fromSec(std::max(0L, base) * monitor_->scenario().timeStep);
    acceptUpTo_ = std::max(acceptUpTo_, static_cast<long>(next.allowed_step));
    const auto at = congruentSinceAt_.find(base);
    next.converged_step = at == congruentSinceAt_.end() ? -1 : at->second;
    congruentSinceAt_.erase(congruentSinceAt_.begin(), congruentSinceAt_.lower_bound(base));
    progress_ = next;
    progressPub_.publish(progress_);
  }
}

std::string MonitorNode::waitingFor() const {
  const long next = monitor_->nextStep();
  if (recording_ && progress_.state != RunProgress::WAITING && recordedStep_ + window_ < next) {
    return "the recorder " + recorder_.node + " (it holds steps up to " + std::to_string(recordedStep_) +
           ", and the agents may not run further ahead of it)";
  }
  const std::vector<int> missing = monitor_->missingAt(next);
  if (!missing.empty()) return "step " + std::to_string(next) + " of " + agentList(missing);
  if (recording_ && recordedStep_ < completedStep()) {
    return "the recorder " + recorder_.node + " (it holds steps up to " + std::to_string(recordedStep_) + ")";
  }
  if (progress_.state == RunProgress::WAITING && waitForViewer_) return "a viewer (rviz) on the markers";
  return "nothing";
}

bool MonitorNode::checkAlive(Participant& p, const std::string& what, double timeout) {
  if (!p.seen) return true;  // not started yet: the waiting line says so
  // An agent in a nodelet manager has no node of its own: its host is the manager.
  const Liveness l = nodeLiveness(p.host.empty() ? p.node : p.host);
  if (l == Liveness::Alive) {
    p.goneSince = ros::WallTime();
    return true;
  }
  if (p.goneSince.isZero()) {
    p.goneSince = ros::WallTime::now();
    if (timeout > 0.0) {
      ROS_WARN("monitor: %s %s is gone (%s%s); waiting up to %.1f s for it to come back", what.c_str(), p.node.c_str(),
               describe(l), p.host.empty() || p.host == p.node ? "" : (", its host " + p.host).c_str(), timeout);
    }
  }
  if (secondsSince(p.goneSince) < timeout) return true;
  finish(RunProgress::FAILED, what + " " + p.node + " ended before the run was over (" + describe(l) +
                                  (p.host.empty() || p.host == p.node ? "" : ", its host " + p.host) + ")");
  return false;
}

void MonitorNode::watch() {
  if (exitStatus_ >= 0) return;
  if (timed_) {
    watchTimed();
    return;
  }
  const ros::WallTime since = lastCompletedAt_.isZero() ? startedAt_ : lastCompletedAt_;
  const double stalled = since.isZero() ? kCheckAfter : secondsSince(since);
  if (stalled >= kCheckAfter) {
    const std::vector<int> missing = monitor_->missingAt(monitor_->nextStep());
    for (int i : missing) {
      if (!checkAlive(agents_[static_cast<std::size_t>(i)], "agent_" + std::to_string(i), respawnTimeout_)) return;
    }
    // A state published while a connection was coming up is lost to this subscriber, but the
    // agent still holds it: catch up from the histories of the agents that are missing.
    if (progress_.state != RunProgress::WAITING && !missing.empty()) {
      const auto held = fetchHistories(missing);
      for (std::size_t k = 0; k < missing.size(); ++k) addHistory(missing[k], held[k]);
      catchUpFromNeighbours(monitor_->missingAt(monitor_->nextStep()));
      publishCompleted();
    }
    if (recording_ && !checkAlive(recorder_, "the recorder", 0.0)) return;
    // A status published while the recorder's connection was coming up (after a restart of
    // either) is lost to it: publish again what it has not recorded; it counts each step once.
    if (recording_ && recordedStep_ < completedStep()) {
      for (const auto& sm : unrecorded_) {
        statusPub_.publish(sm.first);
        if (!sm.second.markers.empty()) markersPub_.publish(sm.second);
      }
    }
  }
  updateProgress();  // a viewer may have come
  if (stalled >= kReportEvery && secondsSince(lastReportAt_) >= kReportEvery) {
    std::vector<int> unseen;
    for (std::size_t i = 0; i < agents_.size(); ++i) {
      if (!agents_[i].seen) unseen.push_back(static_cast<int>(i));
    }
    ROS_INFO("monitor: step %ld complete, waiting for %s%s", completedStep(), waitingFor().c_str(),
             unseen.empty() ? "" : ("; not heard yet: " + agentList(unseen)).c_str());
    lastReportAt_ = ros::WallTime::now();
  }
}

void MonitorNode::writeResult(const std::string& result, const std::string& reason) const {
  if (resultFile_.empty()) return;
  std::ofstream f(resultFile_);
  std::string quoted;
  for (char c : reason) quoted += c == '"' ? std::string("\\\"") : std::string(1, c);
  const FormationOutcome formation = formationOutcome(convergedStep_, finalError_, monitor_->scenario().timeStep);
  f << "result: " << result << "\nscenario: " << monitor_->scenario().name
    << "\nsteps: " << monitor_->scenario().steps << "\ncompleted_step: " << completedStep()
    << "\nconverged_step: " << convergedStep_ << "\nformation: \"" << formation.line
    << "\"\nfinal_max_distance_error: " << finalError_ << "\ndropped: " << dropped_ << "\nreason: \"" << quoted
    << "\"\n";
  if (!f) ROS_ERROR("monitor: cannot write the result file %s", resultFile_.c_str());
}

void MonitorNode::finish(uint8_t state, std::string reason) {
  if (exitStatus_ >= 0) return;
  const long last = completedStep();
  const double h = monitor_->scenario().timeStep;
  const FormationOutcome formation = formationOutcome(convergedStep_, finalError_, h);
  const RunVerdict verdict = finishedRunVerdict(monitor_->scenario(), formation);
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

bool MonitorNode::onRecall(RecallState::Request& request, RecallState::Response& response) {
  response.held = request.id < newest_.size() && newest_[request.id].step >= 0;
  if (response.held) {
    response.step = newest_[request.id].step;
    response.position = newest_[request.id].position;
    response.previous_position = newest_[request.id].previous_position;
  }
  return true;
}

std::vector<RecallHistory::Response> MonitorNode::fetchHistories(const std::vector<int>& ids) {
  std::vector<std::string> services;
  std::vector<RecallHistory> calls(ids.size());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    services.push_back(agents_[static_cast<std::size_t>(ids[k])].node + "/history");
    calls[k].request.id = ids[k];
  }
  const std::vector<bool> answered = callAllWithTimeout(services, calls, 2.0);
  std::vector<RecallHistory::Response> held(ids.size());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (answered[k]) held[k] = calls[k].response;
  }
  return held;
}

void MonitorNode::catchUpFromNeighbours(const std::vector<int>& ids) {
  // A state of an incarnation that died before this monitor got it is held by the neighbours
  // that used it (until the step is complete), and nowhere else.
  std::vector<std::string> services;
  std::vector<RecallHistory> calls;
  std::vector<int> whose;
  for (int i : ids) {
    for (const Neighbour& j : monitor_->formation().neighbours(i)) {
      services.push_back(agents_[static_cast<std::size_t>(j.agent)].node + "/history");
      calls.emplace_back();
      calls.back().request.id = i;
      whose.push_back(i);
    }
  }
  const std::vector<bool> answered = callAllWithTimeout(services, calls, 2.0);
  const long next = monitor_->nextStep();
  for (std::size_t c = 0; c < calls.size(); ++c) {
    if (answered[c]) addHistory(whose[c], calls[c].response);
  }
  const std::vector<int> still = monitor_->missingAt(next);
  for (int i : ids) {
    if (std::find(still.begin(), still.end(), i) == still.end()) {
      ROS_INFO("monitor: step %ld of agent_%d came from its neighbours (the incarnation that published it is gone)",
               next, i);
    }
  }
}

void MonitorNode::addHistory(int agent, const RecallHistory::Response& held) {
  for (const AgentState& s : held.states) {
    if (monitor_->add(agent, s.step, s.position, s.previous_position, acceptUpTo_) !=
        FormationMonitor::Receipt::Accepted) {
      continue;
    }
    if (s.step > newest_[static_cast<std::size_t>(agent)].step) newest_[static_cast<std::size_t>(agent)] = s;
    if (recording_) unrecordedStates_[static_cast<std::size_t>(agent)].push_back(s);
  }
}

bool MonitorNode::onHistory(RecallHistory::Request& request, RecallHistory::Response& response) {
  if (request.id >= 0 && request.id < static_cast<int>(unrecordedStates_.size())) {
    const auto& states = unrecordedStates_[static_cast<std::size_t>(request.id)];
    response.states.assign(states.begin(), states.end());
  }
  response.progress = progress_;
  response.has_progress = true;
  return true;
}

void MonitorNode::recover() {
  // A run in progress has agents that received a progress: ask every agent what it holds.
  std::vector<int> all;
  for (std::size_t i = 0; i < agents_.size(); ++i) all.push_back(static_cast<int>(i));
  const std::vector<RecallHistory::Response> held = fetchHistories(all);
  std::vector<protocol::ProgressAnswer> answers;
  for (const auto& h : held) {
    const bool over = h.progress.state == RunProgress::FINISHED || h.progress.state == RunProgress::FAILED;
    answers.push_back({true, static_cast<bool>(h.has_progress), h.progress.completed_step, h.progress.converged_step,
                       over, h.progress.state == RunProgress::FINISHED});
  }
  const protocol::MonitorResume r = protocol::chooseMonitorResume(answers, window_);
  if (r.over) {  // it did not witness that run: neither its outcome nor a new run is its to report
    finish(RunProgress::FAILED, protocol::describeOver(r));
    return;
  }
  if (!r.resumes()) return;  // a new run
  const long resumeAt = r.step, since = r.congruentSince;
  monitor_->startAt(resumeAt, since);
  reportedConvergence_ = since >= 0 ? since : -2;
  firstStepAt_ = startedAt_ = ros::WallTime::now();
  progress_.state = RunProgress::RUNNING;
  progress_.completed_step = resumeAt - 1;
  acceptUpTo_ = r.acceptUpTo;
  for (std::size_t i = 0; i < held.size(); ++i) {
    agents_[i].seen = true;
    addHistory(static_cast<int>(i), held[i]);
  }
  ROS_INFO("monitor: resuming a run in progress at step %ld (rebuilt from the agents' histories)", resumeAt);
  lastCompletedAt_ = ros::WallTime::now();
  publishCompleted();
}

bool MonitorNode::acceptTimed(int agent, const AgentState& msg, std::string& why) {
  const std::size_t d = static_cast<std::size_t>(monitor_->scenario().dimension);
  bool finite = msg.position.size() == d && msg.previous_position.size() == d;
  for (std::size_t a = 0; finite && a < d; ++a) finite = std::isfinite(msg.position[a]) && std::isfinite(msg.previous_position[a]);
  if (!finite) {
    why = "(step " + std::to_string(msg.step) + "): wrong dimension or not finite";
    return false;
  }
  AgentState& newest = newest_[static_cast<std::size_t>(agent)];
  const double now = ros::WallTime::now().toSec();
  double& at = receivedAt_[static_cast<std::size_t>(agent)];
  // A respawned agent may restart from a lower step once its old state is stale.
  if (msg.step > newest.step || now - at > kCheckAfter) {
    newest = msg;
    at = now;
  }
  return true;
}

void MonitorNode::tickTimed() {
  if (exitStatus_ >= 0) return;
  for (const AgentState& s : newest_) {
    if (s.step < 0) return;  // not every agent is there yet: the run has not started
  }
  ++tick_;
  const double now = ros::WallTime::now().toSec();
  dataAge_ = 0.0;
  bool allDone = monitor_->scenario().steps > 0;
  for (std::size_t i = 0; i < newest_.size(); ++i) {
    const AgentState& s = newest_[i];
    dataAge_ = std::max(dataAge_, now - receivedAt_[i]);
    allDone = allDone && s.step >= monitor_->scenario().steps;
    // The monitor's own step is its tick: it measures the newest state of every agent.
    monitor_->add(static_cast<long>(i), tick_, s.position, s.previous_position, tick_);
  }
  publishCompleted();
  if (allDone && exitStatus_ < 0) finish(RunProgress::FINISHED, "");
}

void MonitorNode::watchTimed() {
  const double now = ros::WallTime::now().toSec();
  for (std::size_t i = 0; i < agents_.size(); ++i) {
    if (agents_[i].seen && now - receivedAt_[i] >= kCheckAfter &&
        !checkAlive(agents_[i], "agent_" + std::to_string(i), respawnTimeout_)) {
      return;
    }
  }
  if (tick_ < 0 && secondsSince(lastReportAt_) >= kReportEvery) {
    std::vector<int> unseen;
    for (std::size_t i = 0; i < agents_.size(); ++i) {
      if (newest_[i].step < 0) unseen.push_back(static_cast<int>(i));
    }
    ROS_INFO("monitor: timed mode, waiting for the first state of %s", agentList(unseen).c_str());
    lastReportAt_ = ros::WallTime::now();
  }
}

int MonitorNode::run() {
  if (!timed_) recover();
  lastReportAt_ = ros::WallTime::now();
  progressPub_.publish(progress_);
  if (timed_) {
    receivedAt_.assign(newest_.size(), 0.0);
    tickTimer_ = nh_.createWallTimer(ros::WallDuration(monitor_->scenario().timeStep / rate_),
                                     [this](const ros::WallTimerEvent&) { tickTimed(); });
    ROS_INFO("monitor: timed mode: status every %g s from each agent's newest state; the Noether predictions do "
             "not hold in this mode (published as NaN)", monitor_->scenario().timeStep / rate_);
  }
  watchTimer_ = nh_.createWallTimer(ros::WallDuration(0.5), [this](const ros::WallTimerEvent&) { watch(); });
  auto* queue = ros::getGlobalCallbackQueue();
  while (ros::ok() && exitStatus_ < 0) queue->callAvailable(ros::WallDuration(0.1));
  if (exitStatus_ < 0) {
    // Shut down from outside (Ctrl-C, roslaunch): an unbounded run is stopped, a bounded one failed.
    if (monitor_->scenario().steps == 0) {
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

}  // namespace vf
