#include "variational_formation_core/protocol/command_desk.hpp"

#include <cmath>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/formation.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/integrators/step_size_advice.hpp"
#include "variational_formation_core/model/validation.hpp"

namespace vf {
namespace protocol {

CommandSchedule appliedSchedule(const Scenario& scenario, const std::vector<IssuedCommand>& issued) {
  CommandSchedule schedule = scheduleFromSegments(scenario.manoeuvre, scenario.timeStep);
  for (const IssuedCommand& c : issued) schedule.replaceFrom(c.first, c.second);
  return schedule;
}

void validateCommandLimits(const CommandLimits& limits) {
  const auto positive = [](const char* name, double value) {
    if (std::isnan(value) || !(value > 0.0)) {
      throw InvalidInput(std::string(name) + ": must be > 0 (or inf: no limit), got " + formatNumber(value));
    }
  };
  positive("~max_speed", limits.maxSpeed);
  positive("~max_turn_rate", limits.maxTurnRate);
  if (std::isnan(limits.minScale) || limits.minScale < 0.0 || std::isinf(limits.minScale)) {
    throw InvalidInput("~min_scale: must be finite and >= 0, got " + formatNumber(limits.minScale));
  }
  if (std::isnan(limits.maxScale) || !(limits.maxScale >= limits.minScale)) {
    throw InvalidInput("~max_scale: must be >= ~min_scale = " + formatNumber(limits.minScale) + ", got " +
                       formatNumber(limits.maxScale));
  }
}

CommandDesk::CommandDesk(const Scenario& scenario, const CommandLimits& limits)
    : scenario_(scenario), limits_(limits), schedule_(scheduleFromSegments(scenario.manoeuvre, scenario.timeStep)) {
  validateCommandLimits(limits);
  const Formation formation = makeFormation(scenario);
  try {
    checkFormationCanTurn(formation, "angular_rate");
  } catch (const InvalidInput& e) {
    canTurn_ = false;
    whyNoTurn_ = e.what();
  }
}

void CommandDesk::modeFrequencies() const {
  if (softest_ >= 0.0) return;
  const Formation formation = makeFormation(scenario_);
  softest_ = minStiffnessFrequency(formation, formation.desiredShape());
  stiffest_ = maxStiffnessFrequency(formation, formation.desiredShape());
}

std::string CommandDesk::turnNote(const Vector3& angularRate, double scale) const {
  modeFrequencies();
  // As validateManoeuvre warns for a scenario's manoeuvre (doc/maths.md §9).
  const double allowed = 0.5 * scale * softest_;
  if (!(angularRate.norm() > allowed)) return "";
  return "|omega*| = " + formatNumber(angularRate.norm()) + " rad/s is above half the softest shape mode's frequency (" +
         formatNumber(allowed) + " rad/s at scale " + formatNumber(scale) +
         "): the turning formation may be slow to take its shape, or lose it";
}

Command CommandDesk::nextAt(long step) const {
  Command c = schedule_.at(step);
  if (pendingVelocity_) {
    c.velocity = velocity_;
    c.angularRate = angularRate_;
  }
  if (pendingScale_) c.scale = scale_;
  return c;
}

bool CommandDesk::acceptable(const Command& c, const std::string& field, std::string& why) const {
  try {
    validateCommand(c, scenario_.dimension, scenario_.timeStep, CommandFieldNames::keys(field));
  } catch (const InvalidInput& e) {
    why = e.what();
    return false;
  }
  if (c.rotates() && !canTurn_) {
    why = whyNoTurn_;
    return false;
  }
  modeFrequencies();
  if (!isLinearlyStable(scenario_.timeStep, c.scale * stiffest_, scenario_.dampingGain)) {
    // The Hessian at the scaled shape is s^2 times the unscaled one: its frequencies grow as s.
    why = field + ": s = " + formatNumber(c.scale) + " puts h = " + formatNumber(scenario_.timeStep) +
          " s above the linear stability limit " +
          formatNumber(stableTimeStepLimit(c.scale * stiffest_, scenario_.dampingGain)) + " s of the scaled shape";
    return false;
  }
  return true;
}

namespace {

/// x scaled down to length `limit` if longer; adds "what |x| = a unit to name = b" to `note`.
Vector3 saturate(const Vector3& x, double limit, const char* what, const char* unit, const char* name, std::string& note) {
  const double length = x.norm();
  if (!(length > limit)) return x;
  note += std::string(note.empty() ? "" : "; ") + what + " = " + formatNumber(length) + " " + unit + " saturated to " +
          name + " = " + formatNumber(limit) + " " + unit;
  return x * (limit / length);
}

}  // namespace

bool CommandDesk::offerVelocity(const Vector3& velocity, const Vector3& angularRate, std::string& why,
                                std::string* note) {
  Command c;
  c.velocity = velocity;
  c.angularRate = angularRate;
  if (!acceptable(c, "cmd_vel", why)) return false;
  std::string said;
  velocity_ = saturate(velocity, limits_.maxSpeed, "|v*|", "m/s", "~max_speed", said);
  angularRate_ = saturate(angularRate, limits_.maxTurnRate, "|omega*|", "rad/s", "~max_turn_rate", said);
  saturated_ += said.empty() ? 0 : 1;
  pendingVelocity_ = true;
  const std::string turn = turnNote(angularRate_, nextAt(issued_.empty() ? 0 : issued_.back().first + 1).scale);
  if (note) *note = said + (said.empty() || turn.empty() ? "" : "; ") + turn;
  return true;
}

bool CommandDesk::offerScale(double scale, std::string& why, std::string* note) {
  std::string said;
  Command c;
  c.scale = scale;
  // Saturated before the stability check: a scale beyond the range runs at its bound. A scale
  // <= 0 or NaN is refused as it stands.
  if (scale > 0.0 && (scale > limits_.maxScale || scale < limits_.minScale)) {
    const bool above = scale > limits_.maxScale;
    c.scale = above ? limits_.maxScale : limits_.minScale;
    said = "s = " + formatNumber(scale) + " saturated to " + (above ? "~max_scale" : "~min_scale") + " = " +
           formatNumber(c.scale);
  }
  if (!acceptable(c, "scale", why)) return false;
  saturated_ += said.empty() ? 0 : 1;
  scale = c.scale;
  scale_ = scale;
  pendingScale_ = true;
  const std::string turn = turnNote(nextAt(issued_.empty() ? 0 : issued_.back().first + 1).angularRate, scale);
  if (note) *note = said + (said.empty() || turn.empty() ? "" : "; ") + turn;
  return true;
}

bool CommandDesk::issue(long allowedStep) {
  if (!pending() || allowedStep < 0) return false;
  if (!issued_.empty() && issued_.back().first >= allowedStep) return false;
  const Command c = nextAt(allowedStep);
  issued_.emplace_back(allowedStep, c);
  schedule_.replaceFrom(allowedStep, c);
  pendingVelocity_ = pendingScale_ = false;
  return true;
}

void CommandDesk::resume(const std::vector<IssuedCommand>& issued) {
  issued_ = issued;
  schedule_ = appliedSchedule(scenario_, issued_);
  pendingVelocity_ = pendingScale_ = false;
}

}  // namespace protocol
}  // namespace vf
