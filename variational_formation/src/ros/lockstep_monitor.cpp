#include <algorithm>

#include "variational_formation_core/protocol/recovery.hpp"
#include "variational_formation/ros/monitor_node.hpp"
#include "variational_formation/ros/liveness.hpp"
#include "variational_formation/ros/participant_names.hpp"
#include "variational_formation/ros/progress_message.hpp"

namespace vf {

namespace {
constexpr double kCheckAfter = 1.0;  // a step stalled this long makes the monitor look for dead participants
constexpr double kReportEvery = 5.0;
}  // namespace

LockstepMonitor::LockstepMonitor(ros::NodeHandle& nh, ros::NodeHandle& pnh) : MonitorNode(nh, pnh, false) {
  referee_ = std::make_unique<Referee>(scenario_, window_, recording_, waitForViewer_);
  if (recording_) {
    const std::string disagree = protocol::checkBuffers(window_);
    if (!disagree.empty()) throw InvalidInput(disagree);
    recorder_.node = participantName(nh, recorderParam_);
    recorderSub_ = nh.subscribe<RunProgress>(
        recorderParam_ + "/progress", 10,
        boost::function<void(const ros::MessageEvent<RunProgress const>&)>(
            [this](const ros::MessageEvent<RunProgress const>& e) { onRecorderProgress(e); }),
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  }
  recallServer_ = pnh.advertiseService("recall", &LockstepMonitor::onRecall, this);
  historyServer_ = pnh.advertiseService("history", &LockstepMonitor::onHistory, this);
  announce(recorder_.node);
}

bool LockstepMonitor::offer(int agent, const AgentState::ConstPtr& msg, const std::string& publisher) {
  std::string why;
  try {
    const auto receipt = referee_->offerState(agent, msg);
    if (receipt == FormationMonitor::Receipt::Accepted || receipt == FormationMonitor::Receipt::Duplicate) {
      heard(agent, publisher);
      return receipt == FormationMonitor::Receipt::Accepted;
    }
    why = "(step " + std::to_string(msg->step) + "): " + FormationMonitor::describe(receipt);
  } catch (const std::exception& e) {
    why = e.what();
  }
  drop(agent, why);
  return false;
}

void LockstepMonitor::onRecorderProgress(const ros::MessageEvent<RunProgress const>& event) {
  if (!fromOwner(event, recorder_.node)) {
    ++dropped_;
    ROS_WARN_THROTTLE(1.0, "monitor: dropped a recorder progress from %s, which is not %s",
                      event.getPublisherName().c_str(), recorder_.node.c_str());
    return;
  }
  const RunProgress& p = *event.getConstMessage();
  recorder_.seen = true;
  recorder_.goneSince = ros::WallTime();
  carryOut(referee_->step(Referee::RecorderReport{p.completed_step, p.state == RunProgress::FINISHED,
                                                  p.state == RunProgress::FAILED ? p.reason : "", viewer()}));
}

void LockstepMonitor::carryOut(const Referee::Ready& r) {
  goalCommandsAt_ = r.commandsAt;  // a goal's command computed from a step below applies there
  for (const FormationSnapshot& s : r.publish) {
    ros::Time stamp;
    stamp.fromSec(s.metrics.time);  // simulated time t_k
    // The Noether predictions are those of the unforced run: NaN under a commanded motion.
    referee_->keep(s.metrics.step, publishSnapshot(s, stamp, 0.0, commandSchedule() == nullptr));
  }
  if (ended()) return;  // a published step was blocked: that Ready ended the run
  const long issuedBefore = commandsIssued();
  if (r.commandsAt >= 0) issueCommands(r.commandsAt);
  if (r.progress || commandsIssued() != issuedBefore) {
    RunProgress next = toMessage(referee_->progressNow());
    next.commands = commandsIssued();
    if (r.starts) startedAt_ = ros::WallTime::now();
    publishProgress(next);
  }
  if (r.finish) finish(referee_->progressNow());
}

void LockstepMonitor::watch() {
  const ros::WallTime since = lastCompletedAt_.isZero() ? startedAt_ : lastCompletedAt_;
  const double stalled = since.isZero() ? kCheckAfter : secondsSince(since);
  if (stalled >= kCheckAfter) {
    const std::vector<int> missing = referee_->missing();
    for (int i : missing) {
      if (!checkAlive(agents_[static_cast<std::size_t>(i)], "agent_" + std::to_string(i), respawnTimeout_)) return;
    }
    // A state published while a connection was coming up is lost to this subscriber, but the
    // agent still holds it: catch up from the histories of the agents that are missing.
    if (progress_.state != RunProgress::WAITING && !missing.empty()) {
      const auto held = fetchHistories(missing);
      for (std::size_t k = 0; k < missing.size(); ++k) referee_->offerHistory(missing[k], sharedStates(held[k].states));
      catchUpFromNeighbours(referee_->missing());
      updateProgress();
    }
    if (recording_ && !checkAlive(recorder_, "the recorder", 0.0)) return;
    // A status published while the recorder's connection was coming up (after a restart of
    // either) is lost to it: publish again what it has not recorded; it counts each step once.
    if (referee_->recorderLags()) {
      for (const auto& kept : referee_->unrecorded()) {
        statusPub_.publish(kept.second.first);
        if (!kept.second.second.markers.empty()) markersPub_.publish(kept.second.second);
      }
    }
  }
  updateProgress();  // a viewer may have come
  if (stalled >= kReportEvery) {
    std::vector<int> unseen;
    for (std::size_t i = 0; i < agents_.size(); ++i) {
      if (!agents_[i].seen) unseen.push_back(static_cast<int>(i));
    }
    reportWaiting("step " + std::to_string(completedStep()) + " complete, waiting for " + waitingFor() +
                  (unseen.empty() ? "" : "; not heard yet: " + agentList(unseen)));
  }
}

bool LockstepMonitor::onRecall(RecallState::Request& request, RecallState::Response& response) {
  const AgentState::ConstPtr* newest =
      request.id < static_cast<std::size_t>(agents_.size()) ? referee_->newest(static_cast<int>(request.id)) : nullptr;
  response.held = newest != nullptr;
  if (response.held) {
    response.step = (*newest)->step;
    response.position = (*newest)->position;
    response.previous_position = (*newest)->previous_position;
  }
  return true;
}

bool LockstepMonitor::onHistory(RecallHistory::Request& request, RecallHistory::Response& response) {
  if (request.id >= 0 && request.id < static_cast<int>(agents_.size())) {
    const auto& states = referee_->unrecordedStates(request.id);
    response.states.reserve(states.size());
    for (const AgentState::ConstPtr& s : states) response.states.push_back(*s);
  }
  response.progress = progress_;
  response.has_progress = true;
  return true;
}

std::vector<RecallHistory::Response> LockstepMonitor::fetchHistories(const std::vector<int>& ids) {
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

void LockstepMonitor::catchUpFromNeighbours(const std::vector<int>& ids) {
  // A state of an incarnation that died before this monitor got it is held by the neighbours
  // that used it (until the step is complete), and nowhere else.
  std::vector<std::string> services;
  std::vector<RecallHistory> calls;
  std::vector<int> whose;
  for (int i : ids) {
    for (const Neighbour& j : measure().formation().neighbours(i)) {
      services.push_back(agents_[static_cast<std::size_t>(j.agent)].node + "/history");
      calls.emplace_back();
      calls.back().request.id = i;
      whose.push_back(i);
    }
  }
  const std::vector<bool> answered = callAllWithTimeout(services, calls, 2.0);
  const long next = completedStep() + 1;
  for (std::size_t c = 0; c < calls.size(); ++c) {
    if (answered[c]) referee_->offerHistory(whose[c], sharedStates(calls[c].response.states));
  }
  const std::vector<int> still = measure().missingAt(next);
  for (int i : ids) {
    if (std::find(still.begin(), still.end(), i) == still.end()) {
      ROS_INFO("monitor: step %ld of agent_%d came from its neighbours (the incarnation that published it is gone)",
               next, i);
    }
  }
}

void LockstepMonitor::begin() {
  // A run in progress has agents that received a progress: ask every agent what it holds.
  std::vector<int> all;
  for (std::size_t i = 0; i < agents_.size(); ++i) all.push_back(static_cast<int>(i));
  const std::vector<RecallHistory::Response> held = fetchHistories(all);
  std::vector<protocol::ProgressAnswer> answers;
  std::vector<std::vector<AgentState::ConstPtr>> histories;
  for (const auto& h : held) {
    const bool over = h.progress.state == RunProgress::FINISHED || h.progress.state == RunProgress::FAILED;
    answers.push_back({true, static_cast<bool>(h.has_progress), h.progress.completed_step, h.progress.converged_step,
                       over, h.progress.state == RunProgress::FINISHED});
    histories.push_back(sharedStates(h.states));
  }
  const Referee::Ready resumed = referee_->step(Referee::Resume{answers, histories});
  // It did not witness a run that is over: neither its outcome nor a new run is its to report.
  carryOut(resumed);
  if (!referee_->running()) {
    if (!ended()) resumeCommands(false);
    return;  // or a new run
  }
  resumeCommands(true);
  if (ended()) return;
  const protocol::MonitorResume& r = referee_->resumedFrom();
  reportedConvergence_ = r.congruentSince >= 0 ? r.congruentSince : -2;
  firstStepAt_ = startedAt_ = ros::WallTime::now();
  progress_ = toMessage(referee_->progressNow());
  progress_.commands = commandsIssued();
  for (Participant& a : agents_) a.seen = true;
  ROS_INFO("monitor: resuming a run in progress at step %ld (rebuilt from the agents' histories)", r.step);
  lastCompletedAt_ = ros::WallTime::now();
  updateProgress();
}

}  // namespace vf
