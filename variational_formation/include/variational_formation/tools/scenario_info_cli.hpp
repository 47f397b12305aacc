#pragma once

#include <iosfwd>

namespace vf {

/**
 * The `scenario_info` tool: validates a scenario (and a pacing factor) through the one
 * validation path and prints "agents N" on out (the launch scripts read it). On err: the
 * scenario's warnings, the graph's generic rigidity class (classifyRigidity), and a warning when
 * the graph is not globally rigid. Bad input is one line on err and kExitBadInput.
 */
int runScenarioInfoCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace vf
