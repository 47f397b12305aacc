#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "variational_formation_core/model/formation.hpp"
#include "variational_formation_core/manoeuvres/command_schedule.hpp"
#include "variational_formation_core/model/slot_assignment.hpp"
#include "variational_formation_core/safety/safety_settings.hpp"

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
  /// Field `mirror` (allowed | forbidden, default forbidden): whether a run that ends in the mirror
  /// image of the desired shape has reached the desired shape (doc/scenarios.md, "Mirror images").
  bool mirrorAllowed = false;
  /// Field `assignment` (auto | none, default none): with auto, loading chose which agent takes which
  /// desired position (assignSlots), and desiredPositions and edges are the agents' after it.
  bool autoAssignment = false;
  /// The assignment made at load (slotOfAgent empty without `assignment: auto`).
  SlotAssignment assignment;
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

/// Largest agent count for `assignment: auto`: every agent runs the O(n^3) Hungarian method at load.
constexpr int kMaxAssignedAgents = 200;

/**
 * Slot assignment (doc/scenarios.md): assignSlots from the initial positions to the desired
 * ones, then agent i takes desired position slotOfAgent[i], and an edge [a, b] of the file,
 * which joins slots a and b, joins the agents that took them. Edges keep their order.
 * Sets scenario.assignment. @throws InvalidInput beyond kMaxAssignedAgents agents.
 */
void applySlotAssignment(Scenario& scenario);

/**
 * Reads start positions, a CSV file "agent,x,y,z" with one row per agent of the scenario in any
 * order (z = 0 in 2D): the robots' current positions for assign_slots.
 * @throws InvalidInput "<file>: line N: <column>: <problem>".
 */
Positions loadStartPositions(const std::string& path, const Scenario& scenario);
/// Parses the text of a start positions file; `source` prefixes error messages.
Positions parseStartPositions(const std::string& csvText, const std::string& source, const Scenario& scenario);

/// The formation (desired shape and edges) of a validated scenario.
Formation makeFormation(const Scenario& scenario);

}  // namespace vf
