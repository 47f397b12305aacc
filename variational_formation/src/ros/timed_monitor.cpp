#include <algorithm>

#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation/ros/monitor_node.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/progress_message.hpp"

namespace vf {

namespace {
constexpr double kStaleAfter = 1.0;  // an agent silent this long is checked for life, and may restart lower
}  // namespace

TimedMonitor::TimedMonitor(ros::NodeHandle& nh, ros::NodeHandle& pnh) : MonitorNode(nh, pnh, true) {
  rate_ = optionalParam(pnh, "real_time_factor", 0.0);
  requireFiniteAbove("~real_time_factor (timed mode: the status period is h / rate)", rate_, 0.0, "");
  referee_ = std::make_unique<protocol::TimedReferee<AgentState>>(scenario_, kStaleAfter, window_, waitForViewer_);
  announce("");
}

bool TimedMonitor::offer(int agent, const AgentState::ConstPtr& msg, const std::string& publisher) {
  std::string why;
  if (!referee_->offerState(agent, *msg, ros::WallTime::now().toSec(), why)) {
    drop(agent, why);
    return false;
  }
  heard(agent, publisher);
  return true;
}

void TimedMonitor::commandOffered() { issueCommands(referee_->commandStep(lastCommandStep())); }

void TimedMonitor::begin() {
  resumeCommands(false);  // agents keep the command they have; a new one replaces it
  tickTimer_ = nh_.createWallTimer(ros::WallDuration(scenario_.timeStep / rate_),
                                   [this](const ros::WallTimerEvent&) {
                                     carryOut(referee_->step(protocol::TimedReferee<AgentState>::Tick{
                                         ros::WallTime::now().toSec(), viewer(),
                                         lastCommandStep()}));
                                   });
  ROS_INFO("monitor: timed mode: status every %g s from each agent's newest state; the Noether predictions do "
           "not hold in this mode (published as NaN)", scenario_.timeStep / rate_);
}

void TimedMonitor::carryOut(const protocol::RefereeReady& r) {
  goalCommandsAt_ = r.commandsAt;
  for (const FormationSnapshot& s : r.publish) publishSnapshot(s, stampOf(s.metrics.step), referee_->dataAge(), false);
  if (ended()) return;  // a published step was blocked: that Ready ended the run
  if (r.commandsAt >= 0) issueCommands(r.commandsAt);  // a goal's command (GoalServer) goes out at once
  if (r.progress) {
    if (r.starts) startedAt_ = ros::WallTime::now();
    publishProgress(toMessage(referee_->progressNow()));
  }
  if (r.finish) finish(referee_->progressNow());
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
