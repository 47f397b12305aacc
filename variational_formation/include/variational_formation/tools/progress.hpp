#pragma once

#include <iosfwd>

namespace vf {

/// Redraws a 40-character progress bar "[####    ] done/total" on the current line of err.
void drawProgressBar(std::ostream& err, long done, long total);

}  // namespace vf
