#pragma once

#include <iosfwd>

namespace vf {

/// Exit statuses of the command-line tools.
enum ExitStatus { kExitOk = 0, kExitFailure = 1, kExitBadInput = 2 };

/**
 * The `simulate` tool (doc/architecture.md, file formats): runs a scenario centrally and writes traj.csv and,
 * optionally, metrics.csv. Bad input is one line on err and kExitBadInput.
 */
int runSimulateCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace vf
