#pragma once

#include <iosfwd>

namespace vf {

/**
 * The `assign_slots` tool: reads a scenario and the robots' current positions (a CSV file
 * "agent,x,y,z", loadStartPositions), makes them the starts, chooses the slot assignment
 * (applySlotAssignment, as `assignment: auto` would at load) and writes the scenario with the
 * starts, the assigned desired positions and edges, and no `assignment:` field, so that it
 * launches as it is. Every other field is kept. Bad input is one line on err and kExitBadInput.
 */
int runAssignSlotsCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace vf
