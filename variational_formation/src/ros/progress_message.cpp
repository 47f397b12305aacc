// RunProgress to and from protocol::Progress: the one place that maps the message's states.
#include "variational_formation/ros/progress_message.hpp"

namespace vf {

using variational_formation_msgs::RunProgress;

namespace {
uint8_t toMessageState(protocol::Progress::State s) {
  switch (s) {
    case protocol::Progress::State::Waiting: return RunProgress::WAITING;
    case protocol::Progress::State::Running: return RunProgress::RUNNING;
    case protocol::Progress::State::Finished: return RunProgress::FINISHED;
    case protocol::Progress::State::Failed: break;
  }
  return RunProgress::FAILED;
}

protocol::Progress::State stateOf(uint8_t s) {
  switch (s) {
    case RunProgress::WAITING: return protocol::Progress::State::Waiting;
    case RunProgress::RUNNING: return protocol::Progress::State::Running;
    case RunProgress::FINISHED: return protocol::Progress::State::Finished;
    default: return protocol::Progress::State::Failed;
  }
}
}  // namespace

RunProgress toMessage(const protocol::Progress& p) {
  RunProgress m;
  m.state = toMessageState(p.state);
  m.completed_step = p.completedStep;
  m.allowed_step = p.allowedStep;
  m.converged_step = p.convergedStep;
  m.reason = p.reason;
  return m;
}

protocol::AgentProgress agentProgressOf(const RunProgress& m) {
  protocol::AgentProgress a;
  a.progress.state = stateOf(m.state);
  a.progress.completedStep = m.completed_step;
  a.progress.allowedStep = m.allowed_step;
  a.progress.convergedStep = m.converged_step;
  a.progress.reason = m.reason;
  a.commands = m.commands;
  return a;
}

}  // namespace vf
