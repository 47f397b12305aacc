#pragma once

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "variational_formation_core/manoeuvres/command_schedule.hpp"
#include "variational_formation_core/model/scenario.hpp"

namespace vf {
namespace protocol {

/// One issued command: the step from which it applies, and the command.
using IssuedCommand = std::pair<long, Command>;

/**
 * The scenario's own schedule (its `manoeuvre:`) with the issued commands applied in order, each
 * replacing the schedule from its step on (CommandSchedule::replaceFrom): what every agent
 * applies, and what a `simulate --commands` file must hold to compute the same run.
 */
CommandSchedule appliedSchedule(const Scenario& scenario, const std::vector<IssuedCommand>& issued);

/**
 * The formation's limits on live commands (the monitor's ~max_speed, ~max_turn_rate, ~min_scale
 * and ~max_scale; doc/manoeuvres.md): a command beyond one is saturated to it, not refused. None
 * by default.
 */
struct CommandLimits {
  double maxSpeed = std::numeric_limits<double>::infinity();     ///< |v*| [m/s] > 0
  double maxTurnRate = std::numeric_limits<double>::infinity();  ///< |omega*| [rad/s] > 0
  double minScale = 0.0;                                         ///< s >= 0
  double maxScale = std::numeric_limits<double>::infinity();     ///< s >= minScale
};

/// maxSpeed, maxTurnRate > 0, 0 <= minScale <= maxScale, none NaN (infinity: no limit).
/// @throws InvalidInput naming the monitor parameter.
void validateCommandLimits(const CommandLimits& limits);

/**
 * The monitor's side of live commands in a lockstep run (doc/protocol.md, "Commands"), without a
 * transport. Inputs are the two halves of a command: a velocity (cmd_vel: v*, omega*) and a scale
 * (s); each is checked (validateCommand, and whether the formation can turn) and, if good, makes
 * a pending command: the one that applies at the next issue with that half replaced.
 *
 * Issue: a pending command is stamped with the allowed step A of the progress the monitor has
 * published (agents hold at most q_A, and the update from A uses intervals A - 1 and A, so a
 * command for interval A reaches every agent in time), at most one per value of A: a second
 * input before A moves stays pending and is issued, merged, at the next A. The monitor publishes
 * the list before any progress that allows a step beyond A, and that progress counts the list;
 * an agent steps only while it holds that many commands.
 *
 * Checks, in order: refused as a scenario's manoeuvre would be (validateCommand: NaN, a 3D part
 * in 2D, a turn of more than 0.1 rad per step), or a turn the formation cannot make, or a scale
 * whose shape breaks the linear stability limit of h; then saturated to the limits (counted);
 * then, like a scenario's manoeuvre, a note if |omega*| is above half the softest shape mode's
 * frequency at the scale it will run at.
 */
class CommandDesk {
 public:
  /// @param scenario validated (its dimension, h, manoeuvre and formation); @param limits validated.
  explicit CommandDesk(const Scenario& scenario, const CommandLimits& limits = CommandLimits());

  /**
   * A velocity command (v*, omega*). @return false with `why` (one line) if it is refused.
   * @param note if given: "" or one line on what was saturated and what to expect (a WARN).
   */
  bool offerVelocity(const Vector3& velocity, const Vector3& angularRate, std::string& why,
                     std::string* note = nullptr);
  /// A scale command (s). @return false with `why` if it is refused; `note` as offerVelocity.
  bool offerScale(double scale, std::string& why, std::string* note = nullptr);
  /// Commands saturated to the limits so far.
  long saturated() const { return saturated_; }

  /// A command waits to be issued.
  bool pending() const { return pendingVelocity_ || pendingScale_; }
  /**
   * Issues the pending command at `allowedStep` (>= 0) if there is one and nothing was issued at
   * this step or later yet. @return whether it issued one.
   */
  bool issue(long allowedStep);

  /// Every command issued so far, oldest first.
  const std::vector<IssuedCommand>& issued() const { return issued_; }
  /// The schedule the agents apply (appliedSchedule of the issued commands).
  const CommandSchedule& schedule() const { return schedule_; }

  /**
   * A restarted monitor goes on from what the monitor before it issued (kept on the parameter
   * server before it was published, so nothing an agent applied is missing). Replaces the issued
   * list and the schedule; nothing is pending.
   */
  void resume(const std::vector<IssuedCommand>& issued);

 private:
  /// The command of the next issue: what the schedule has at that step, with the offered halves.
  Command nextAt(long step) const;
  /// validateCommand (fields named `field`.velocity, ...) and, if it turns, whether the formation
  /// can; false with `why` otherwise.
  bool acceptable(const Command& command, const std::string& field, std::string& why) const;
  /// The note on |omega*| against half the softest mode's frequency at scale s ("" if below).
  std::string turnNote(const Vector3& angularRate, double scale) const;

  Scenario scenario_;
  CommandLimits limits_;
  /// The shape modes' softest and stiffest frequencies at s = 1 [rad/s], computed at the first
  /// command (an eigensolve of the Hessian: seconds for a thousand agents, none without commands).
  void modeFrequencies() const;
  mutable double softest_ = -1.0, stiffest_ = -1.0;
  long saturated_ = 0;
  bool canTurn_ = true;
  std::string whyNoTurn_;
  bool pendingVelocity_ = false, pendingScale_ = false;
  Vector3 velocity_ = Vector3::Zero(), angularRate_ = Vector3::Zero();
  double scale_ = 1.0;
  std::vector<IssuedCommand> issued_;
  CommandSchedule schedule_;
};

}  // namespace protocol
}  // namespace vf
