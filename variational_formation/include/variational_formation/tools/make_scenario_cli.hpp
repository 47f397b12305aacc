#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "variational_formation_core/model/scenario.hpp"

namespace vf {

/**
 * The `make_scenario` tool: writes a rigid formation scenario (a triangulated grid, a ring
 * with chords, a braced 3D lattice or a random Henneberg construction) with a seeded
 * perturbation of the start, to --out or to out. It refuses a graph that fails the core's
 * infinitesimal rigidity rank test. Bad input is one line on err and kExitBadInput.
 */
int runMakeScenarioCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

/**
 * Writes a scenario in the format loadScenario reads, every number with 17 significant
 * digits so that loading it gives back the same doubles. Each comment becomes a "# " line.
 */
void writeScenarioYaml(const Scenario& scenario, const std::vector<std::string>& comments,
                       std::ostream& out);

}  // namespace vf
