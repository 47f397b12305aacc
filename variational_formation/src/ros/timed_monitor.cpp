#include <algorithm>

#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation/ros/monitor_node.hpp"
#include "variational_formation/ros/parameters.hpp"

namespace vf {

namespace {
constexpr double kStaleAfter = 1.0;  // an agent silent this long is checked for life, and may restart lower
}  // namespace

TimedMonitor::TimedMonitor(ros::NodeHandle& nh, ros::NodeHandle& pnh) : MonitorNode(nh, pnh, true) {
  rate_ = optionalParam(pnh, "real_time_factor", 0.0);
  requireFiniteAbove("~real_time_factor (timed mode: the status period is h / rate)", rate_, 0.0, "");
  referee_ = std::make_unique<protocol::TimedReferee<AgentState>>(scenario_, kStaleAfter);
  announce("");
}

bool TimedMonitor::offer(int agent, const AgentState& msg, const std::string& publisher) {
  std::string why;
  if (!referee_->offerState(agent, msg, ros::WallTime::now().toSec(), why)) {
    drop(agent, why);
    return false;
  }
  heard(agent, publisher);
  return true;
}

void TimedMonitor::commandOffered() {
  // Stamped with the monitor's tick (after the last issued one); the agents take the newest.
  long step = completedStep() + 1;
  if (!desk_->issued().empty()) step = std::max(step, desk_->issued().back().first + 1);
  issueCommands(step);
}

void TimedMonitor::begin() {
  resumeCommands(false);  // agents keep the command they have; a new one replaces it
  tickTimer_ = nh_.createWallTimer(ros::WallDuration(scenario_.timeStep / rate_),
                                   [this](const ros::WallTimerEvent&) { tick(); });
  ROS_INFO("monitor: timed mode: status every %g s from each agent's newest state; the Noether predictions do "
           "not hold in this mode (published as NaN)", scenario_.timeStep / rate_);
}

void TimedMonitor::tick() {
  if (ended()) return;
  const std::vector<FormationSnapshot> done = referee_->tick(ros::WallTime::now().toSec());
  if (done.empty()) return;  // not every agent is there yet: the run has not started
  for (const FormationSnapshot& s : done) {
    publishSnapshot(s, stampOf(s.metrics.step), referee_->dataAge(), false);
  }
  if (ended()) return;  // a blocked formation ended the run (monitor_safety.cpp)
  if (desk_->pending()) commandOffered();  // a goal's command (GoalServer): timed mode issues at once
  // The progress starts the agents at the first tick (start by identity, as in lockstep); after
  // that they ignore the window, and it says every quarter window how far the run is.
  const long completed = completedStep(), last = scenario_.steps;
  if (last > 0 && completed >= last) {
    finish(RunProgress::FINISHED, "");
    return;
  }
  const bool viewer = !waitForViewer_ || markersPub_.getNumSubscribers() > 0;
  const bool starts = progress_.state == RunProgress::WAITING;
  if (!(starts ? viewer : completed >= progress_.completed_step + std::max<long>(1, window_ / 4))) {
    if (referee_->finished()) finish(RunProgress::FINISHED, "");
    return;
  }
  if (starts) startedAt_ = ros::WallTime::now();
  RunProgress next = progress_;
  next.state = RunProgress::RUNNING;
  next.completed_step = completed;
  next.allowed_step = last > 0 ? std::min(completed + window_, last) : completed + window_;
  next.converged_step = convergedStep_;
  publishProgress(next);
  if (referee_->finished()) finish(RunProgress::FINISHED, "");
}

void TimedMonitor::watch() {
  for (int i : referee_->silent(ros::WallTime::now().toSec())) {
    if (!checkAlive(agents_[static_cast<std::size_t>(i)], "agent_" + std::to_string(i), respawnTimeout_)) return;
  }
  if (!referee_->started()) reportWaiting("timed mode, waiting for " + waitingFor());
  reportRobotsMissing();
}

std::string TimedMonitor::waitingFor() const {
  const std::vector<int> unheard = referee_->unheard();
  if (!unheard.empty()) return "the first state of " + agentList(unheard);
  return "nothing";
}

}  // namespace vf
