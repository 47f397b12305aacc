#pragma once

#include <limits>
#include <optional>
#include <string>

#include "variational_formation_core/model/scenario.hpp"

namespace vf {

/**
 * The one validation path for the numbers of a run: a scenario file, command-line overrides and
 * node parameters all go through these functions, so each value is rejected once, with one
 * line "<field>: <problem>, got <value> (<limit>)", and the warnings are computed once.
 * The limits are listed in README ("Limits").
 */
namespace limits {
/// Smallest positive normal double. Every gain of the update (e^{-kappa h}, 2h^2/(1 + e^{kappa h}),
/// 2h/(1 + e^{kappa h})) must be at least this: a denormal gain has lost precision, a zero one
/// freezes the agents.
constexpr double kSmallestGain = std::numeric_limits<double>::min();
/// Largest kappa h [1]: -ln(kSmallestGain), so that e^{-kappa h} is a normal double (e^{kappa h}
/// itself would overflow only past 709.78).
constexpr double kMaxDampingTimeStep = 708.3964185322641;
/// Largest h [s] for which 2 h^2 is finite: (2h) h is evaluated by the update's gain.
constexpr double kMaxTimeStep = 9.480751908109176e153;
/// Largest number of steps: step indices up to 2^53 convert to double exactly (t_k = k h).
constexpr long kMaxSteps = 9007199254740992L;
/// Longest pacing sleep h / real_time_factor [s]: a ROS duration holds int32 seconds.
constexpr double kMaxPacingSeconds = 2147483647.0;
/// Largest turn per step h |omega*| [rad] of a command (doc/maths.md §9: the rates tested stable
/// are far below it; beyond it the rotation per step is too coarse to be tracked).
constexpr double kMaxTurnPerStep = 0.1;
}  // namespace limits

/// The names under which values are reported: the scenario's fields, or the flags that set them.
struct FieldNames {
  std::string dampingGain = "kappa";
  std::string timeStep = "time_step";
  std::string steps = "steps";
};

/**
 * Checks h [s] and kappa [1/s]: finite, h > 0, kappa >= 0, h <= limits::kMaxTimeStep,
 * kappa h <= limits::kMaxDampingTimeStep, and every gain of the update a normal double.
 * @throws InvalidInput naming the field, the value and the limit.
 */
void validateDynamics(double timeStep, double dampingGain, const FieldNames& names = {});
/// validateDynamics without the throw: the message, or "" if h and kappa are accepted.
std::string dynamicsProblem(double timeStep, double dampingGain, const FieldNames& names = {});

/// The largest kappa [1/s] that validateDynamics accepts at time step h [s] (the accepted range
/// is [0, that]), exactly. @throws InvalidInput if h itself is refused.
double maxDampingGain(double timeStep);

/**
 * A new kappa [1/s] for a running formation or agent (dynamic_reconfigure), checked by
 * validateDynamics at the run's h [s]. @return nothing if `requested` is accepted; else one line
 * for a warning: `field`, the value given, the accepted range [0, maxDampingGain] and that
 * `current` is kept.
 */
std::optional<std::string> refuseDampingGain(double timeStep, double requested, double current,
                                             const std::string& field);

/// Checks a step count: 0 <= steps <= limits::kMaxSteps, and steps >= 1 if requireBounded
/// (0 = unbounded is only for the ROS run). @throws InvalidInput naming `field`.
void validateSteps(long steps, bool requireBounded, const std::string& field = "steps");

/**
 * Checks a real-time factor (0 = as fast as possible): finite, >= 0, and if > 0 the pacing
 * duration h / realTimeFactor at most limits::kMaxPacingSeconds.
 * @param timeStep h [s] of the (validated) scenario. @throws InvalidInput naming `field`.
 */
void validateRealTimeFactor(double realTimeFactor, double timeStep,
                            const std::string& field = "real_time_factor");

/// The names under which a command's values are reported.
struct CommandFieldNames {
  std::string velocity, angularRate, scale;
  /// A `manoeuvre:` segment's keys: "<prefix>.velocity", ".angular_rate", ".scale".
  static CommandFieldNames keys(const std::string& prefix);
  /// A commands file's columns: "<prefix>: vx,vy,vz", ": wx,wy,wz", ": scale".
  static CommandFieldNames columns(const std::string& prefix);
};

/**
 * The one check of a command (doc/manoeuvres.md), whether from a scenario's `manoeuvre:`, a
 * commands file or a message: every number finite, scale > 0, in 2D no z velocity and no x, y
 * angular rate, and h |omega*| <= limits::kMaxTurnPerStep.
 * @param timeStep h [s] of the (validated) run. @throws InvalidInput naming the field.
 */
void validateCommand(const Command& command, int dimension, double timeStep, const CommandFieldNames& names);

/**
 * Turning needs every agent's motion parameters to be exact (motion_parameters.hpp).
 * @throws InvalidInput "<field>: agent i cannot know its offset from the centroid: ..." for
 * the first agent that does not qualify.
 */
void checkFormationCanTurn(const Formation& formation, const std::string& field);

/**
 * Checks the numeric fields (validateDynamics, validateSteps) and the formation, and recomputes
 * the warnings (a non-rigid desired graph, h above the linear stability limit).
 * @throws InvalidInput naming the field.
 */
void validateScenario(Scenario& scenario, bool requireBoundedSteps = false,
                      const FieldNames& names = {});

/**
 * Checks a scenario's `manoeuvre:` (part of validateScenario): until values > 0 and increasing,
 * each segment through validateCommand, and checkFormationCanTurn if any segment turns.
 * Appends warnings (kappa = 0 cannot track a velocity or rate; h against the stiffer scaled shape).
 */
void validateManoeuvre(Scenario& scenario, const Formation& formation, const FieldNames& names = {});

/**
 * Checks a scenario's `safety:` and `obstacles:` (part of validateScenario; doc/scenarios.md):
 * r > 0, sensing_radius > r, γ in (0, 1], max_speed and blocked_after > 0, obstacles only with
 * safety, radius >= 0 and min <= max; no two desired positions closer than r (at the
 * manoeuvre's smallest scale if it shrinks the shape), no two starts closer than r, and no start
 * closer than r/2 to an obstacle. Appends a warning when steps are long enough to cross the gap
 * R - r between sensing and contact.
 * @throws InvalidInput naming the field, the value and why.
 */
void validateSafety(Scenario& scenario);

/// The initial headings (`initial_heading`): none, or one finite value [rad] per agent, planar
/// scenarios only. @throws InvalidInput naming the field.
void validateInitialHeadings(const Scenario& scenario);

/// Agent id's initial heading [rad] from the scenario (0 if it gives none).
/// @throws InvalidInput on a bad id.
double initialHeading(const Scenario& scenario, int id);

/// Replacements for scenario fields (command-line flags); unset ones keep the file's value.
struct ScenarioOverrides {
  std::optional<double> timeStep;
  std::optional<double> dampingGain;
  std::optional<long> steps;
};

/**
 * Applies the overrides and validates the result again, warnings included. Errors and warnings
 * about an overridden value name the flag ("--time-step", "--kappa", "--steps").
 * @throws InvalidInput naming the field or flag.
 */
void applyOverrides(Scenario& scenario, const ScenarioOverrides& overrides,
                    bool requireBoundedSteps);

}  // namespace vf
