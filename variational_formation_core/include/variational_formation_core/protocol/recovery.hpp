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
  bool over = false;         ///< that progress ended the run (finished or failed)
  bool finished = false;     ///< ... and it finished
};

/// Where a restarted lockstep monitor goes on.
struct MonitorResume {
  long step = 0;            ///< first step not known to be complete (0: a new run)
  long congruentSince = -1; ///< first step of the congruent stretch holding at step - 1
  /// States past this step cannot come yet: the old monitor may have allowed its own completed
  /// step (at most a quarter window past what the agents heard) plus the window.
  long acceptUpTo = 0;
  /// Some agent heard the final progress of its run: the run is over, and a monitor started
  /// now did not witness it; it must neither resume nor report that run's outcome.
  bool over = false;
  bool finished = false;   ///< the run over finished (else it failed)
  long overAt = -1;        ///< the completed step of that final progress
  bool resumes() const { return !over && step > 0; }
};

/// The one line a monitor started against the agents of a run that is over says (empty if not over).
std::string describeOver(const MonitorResume& r);

/// The newest progress any agent heard decides; `window` is the monitor's ~window (>= 1). If any
/// agent heard a final progress (finished or failed), the agents' run is over (MonitorResume::over).
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
