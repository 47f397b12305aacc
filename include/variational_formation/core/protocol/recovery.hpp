#pragma once

#include <string>
#include <vector>

namespace vf::protocol {

/// One holder's answer to a restarted agent's "what do you hold of me" (the `~recall` service).
struct RecallAnswer {
  bool answered = false;  ///< the call returned in time
  bool held = false;      ///< the holder has a state of the agent
  long step = -1;         ///< its step, if held
};

/**
 * Where a restarted agent resumes (lockstep and timed alike): from the holder with the newest
 * held step beyond 0; the first such holder wins a tie (neighbours are asked before the monitor).
 * @return the index of that answer, or -1: nobody holds more than step 0, so start from the scenario.
 */
int chooseAgentResume(const std::vector<RecallAnswer>& answers);

/// One agent's answer to a restarted monitor's `~history` call: the last progress it heard.
struct ProgressAnswer {
  bool answered = false;     ///< the call returned in time
  bool hasProgress = false;  ///< the agent has heard a progress
  long completedStep = -1;   ///< that progress' completed step
  long convergedStep = -1;   ///< and its first step of the congruent stretch (-1 if none)
};

/// Where a restarted lockstep monitor goes on.
struct MonitorResume {
  long step = 0;            ///< first step not known to be complete (0: a new run)
  long congruentSince = -1; ///< first step of the congruent stretch holding at step - 1
  /// States past this step cannot come yet: the old monitor may have allowed its own completed
  /// step (at most a quarter window past what the agents heard) plus the window.
  long acceptUpTo = 0;
  bool resumes() const { return step > 0; }
};

/// The newest progress any agent heard decides; `window` is the monitor's ~window (>= 1).
MonitorResume chooseMonitorResume(const std::vector<ProgressAnswer>& answers, long window);

/// The recorder's fixed buffers: its subscriber queues and how many steps of each agent it keeps
/// to compare repeats with.
struct RecorderBuffers {
  long queue = 100000;
  long keptSteps = 1024;
};

/**
 * How far past the recorder's completed step a message can be while the monitor's window holds:
 * the window, a quarter window of progress not yet republished, and a restarted monitor's
 * acceptUpTo slack (another quarter). A repeat is never older than that behind an agent's newest.
 */
long recorderLead(long window);

/// The largest window whose recorderLead fits both buffers (0 if none does).
long maxWindow(const RecorderBuffers& buffers);

/**
 * Checks the monitor's window against the recorder's buffers.
 * @return "" if they agree, else one line saying which buffer is too small for which window.
 */
std::string checkBuffers(long window, const RecorderBuffers& buffers = RecorderBuffers());

}  // namespace vf::protocol
