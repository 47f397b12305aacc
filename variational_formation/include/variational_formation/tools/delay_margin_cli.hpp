#pragma once

#include <iosfwd>

namespace vf {

/**
 * The `delay_margin` tool: predicts the delay margin of a scenario from the linearised delayed
 * recurrence, sweeps delay x loss with many simulations per cell, writes one CSV per cell and a
 * summary CSV, and prints the predicted and the simulated margin. Bad input: one line on err,
 * exit status 2.
 */
int runDelayMarginCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err,
                      bool progressToTerminal);

}  // namespace vf
