#pragma once

#include <string>
#include <vector>

#include "variational_formation_core/agents/formation_monitor.hpp"
#include "variational_formation_core/protocol/progress.hpp"

namespace vf::protocol {

/// A failure the monitor found: an agent's (its divergence, a command it refused), a participant
/// gone, the kept commands unreadable, the recorder's. The referee fails the run with `reason`.
struct Failure {
  std::string reason;
};

/// The safety filter found the formation blocked at a published step: the run ends there as
/// finished (the shape verdict then says that it did not form, blocked).
struct Blocked {};

/**
 * What a monitor node does after a referee's event (LockstepReferee, TimedReferee), in this
 * order. The node decides nothing of it; it only carries it out.
 */
struct RefereeReady {
  /// 1. The completed steps, oldest first: publish each (status, markers); in lockstep keep what
  ///    went out for the recorder (LockstepReferee::keep). A published step that the node's safety
  ///    watch finds blocked is a Blocked event, whose Ready ends the run: the rest of this one is
  ///    then void.
  std::vector<FormationSnapshot> publish;
  /// 2. >= 0: issue the pending commands, stamped with this step (CommandDesk::issue), before any
  ///    progress that counts them.
  long commandsAt = -1;
  /// 3. Publish the referee's progressNow(); in lockstep also when 2 issued a command (the
  ///    progress counts the issued commands there, RunProgress.commands).
  bool progress = false;
  /// The progress of 3 starts the run (the node notes when).
  bool starts = false;
  /// 4. The run is over: end it as progressNow() says (state, reason): the shape verdict, the
  ///    result file, the final progress and the last line.
  bool finish = false;
};

/**
 * Ends the run in `progress` once: a second end changes nothing.
 * @return the Ready that finishes it, empty if the run was already over.
 */
inline RefereeReady endRun(Progress& progress, Progress::State state, const std::string& reason) {
  RefereeReady r;
  if (over(progress)) return r;
  progress.state = state;
  progress.reason = reason;
  r.finish = true;
  return r;
}

}  // namespace vf::protocol
