#pragma once

#include <iosfwd>

namespace vf {

/**
 * The `roa` tool: a region-of-attraction campaign (paper Section 6.2) written to roa.csv
 * (`ix,iy,x,y,converged,converged_step,diverged`). Bad input: one line on err, exit status 2.
 * @param progressToTerminal draw a progress bar on err (when it is a terminal).
 */
int runRoaCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err,
              bool progressToTerminal);

}  // namespace vf
