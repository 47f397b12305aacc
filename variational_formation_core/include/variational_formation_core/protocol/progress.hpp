#pragma once

#include <string>

namespace vf::protocol {

/// The run's flow state as the monitor publishes it (`progress`, RunProgress.msg).
struct Progress {
  enum class State { Waiting, Running, Finished, Failed };
  State state = State::Waiting;
  long completedStep = -1;  ///< every step up to here is complete (and recorded, if recording)
  long allowedStep = 0;     ///< agents may compute up to this step
  long convergedStep = -1;  ///< first step of the congruent stretch holding at completedStep
  std::string reason;       ///< why it failed
};

/// The monitor's `progress` as an agent reads it: the flow state and the commands it counts.
struct AgentProgress {
  Progress progress;
  long commands = 0;  ///< commands of the monitor's list issued so far; an agent steps only while it holds them all
};

/// The run is over (finished or failed): no step follows.
inline bool over(const Progress& p) {
  return p.state == Progress::State::Finished || p.state == Progress::State::Failed;
}

}  // namespace vf::protocol
