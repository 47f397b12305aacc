#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>

#include "variational_formation_core/model/scenario.hpp"

namespace vf {

class Arguments;

/**
 * Starts as robots are parked (issue 31): uniform in a square (2D) or cube (3D) of side `side`
 * centred on the desired shape's centroid, each at least `minGap` from every earlier one
 * (rejection sampling; the same positions for a seed on every platform).
 * @param side [m] > 0. @param minGap [m] >= 0.
 * @throws InvalidInput naming --scatter or --min-gap if the agents do not fit.
 */
Positions scatteredPositions(const Positions& desired, double side, double minGap, std::uint64_t seed);

/// make_scenario's deployment flags (doc/scenarios.md): --scatter SIDE [--min-gap G] replaces
/// the perturbed start, --safety r R GAMMA [--max-speed V] adds a `safety:` block, which is then
/// validated. @return the comment line that describes the start ("" if --scatter is not given).
/// @throws InvalidInput naming the flag.
std::string applyDeploymentFlags(const Arguments& args, std::uint64_t seed, Scenario& scenario);

/// Writes the scenario's `safety:` block and `obstacles:` list as YAML (nothing without them).
void writeSafetyYaml(const Scenario& scenario, std::ostream& out);

}  // namespace vf
