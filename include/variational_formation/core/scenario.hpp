#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "variational_formation/core/formation.hpp"
#include "variational_formation/core/manoeuvre_command.hpp"
#include "variational_formation/core/safety.hpp"

namespace vf {

/**
 * One scenario file (doc/architecture.md, file formats). Loaded and checked by one path, shared by the CLIs and the
 * nodes. Positions are d x n, agents in id order.
 */
struct Scenario {
  std::string name;
  int dimension = 0;
  double dampingGain = 0.0;  ///< kappa [1/s]
  double timeStep = 0.0;     ///< h [s]
  long steps = 0;            ///< number of updates; 0 = unbounded (ROS run only)
  Positions initialPositions;
  Velocities initialVelocities;
  Positions desiredPositions;
  std::vector<std::pair<int, int>> edges;
  /// The optional `manoeuvre:` schedule (doc/manoeuvres.md); empty = no command, today's run.
  /// The last segment's until is +inf when omitted.
  std::vector<ManoeuvreSegment> manoeuvre;
  /// Initial heading [rad] of each agent's unicycle robot (field `initial_heading`, 2D only):
  /// empty if no agent gives one, else one per agent (0 where not given).
  std::vector<double> initialHeadings;
  /// Field `require_convergence` (default false): a run whose formation is not congruent with
  /// the desired shape at its end fails (doc/scenarios.md); otherwise it succeeds and says so.
  bool requireConvergence = false;
  /// The optional `safety:` block (doc/scenarios.md): every step goes through the safety filter.
  std::optional<SafetySettings> safety;
  /// The optional `obstacles:` list (only with `safety:`).
  std::vector<Obstacle> obstacles;
  /// Non-fatal findings, one line each (a non-rigid desired graph, a too large h).
  std::vector<std::string> warnings;

  int agentCount() const { return static_cast<int>(initialPositions.cols()); }
};

/// Reads a scenario file and validates it (validateScenario, validation.hpp).
/// @throws InvalidInput "<file>: <field>: <problem>".
Scenario loadScenario(const std::string& path);
/// Parses and validates YAML text; `source` prefixes error messages.
Scenario parseScenario(const std::string& yamlText, const std::string& source);
/**
 * Reads a commands file "step,vx,vy,vz,wx,wy,wz,scale" (doc/manoeuvres.md) for a validated
 * scenario; every row goes through validateCommand, like the scenario's `manoeuvre:` segments.
 * @throws InvalidInput "<file>: line N: <column>: <problem>".
 */
CommandSchedule loadCommands(const std::string& path, const Scenario& scenario);
/// Parses the text of a commands file; `source` prefixes error messages.
CommandSchedule parseCommands(const std::string& csvText, const std::string& source, const Scenario& scenario);

/// The formation (desired shape and edges) of a validated scenario.
Formation makeFormation(const Scenario& scenario);

}  // namespace vf
