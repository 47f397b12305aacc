#include "variational_formation/core/protocol/command_desk.hpp"

#include "variational_formation/core/error.hpp"
#include "variational_formation/core/formation.hpp"
#include "variational_formation/core/validation.hpp"

namespace vf {
namespace protocol {

CommandSchedule appliedSchedule(const Scenario& scenario, const std::vector<IssuedCommand>& issued) {
  CommandSchedule schedule = scheduleFromSegments(scenario.manoeuvre, scenario.timeStep);
  for (const IssuedCommand& c : issued) schedule.replaceFrom(c.first, c.second);
  return schedule;
}

CommandDesk::CommandDesk(const Scenario& scenario) : scenario_(scenario), schedule_(scheduleFromSegments(scenario.manoeuvre, scenario.timeStep)) {
  try {
    checkFormationCanTurn(makeFormation(scenario), "angular_rate");
  } catch (const InvalidInput& e) {
    canTurn_ = false;
    whyNoTurn_ = e.what();
  }
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
  return true;
}

bool CommandDesk::offerVelocity(const Vector3& velocity, const Vector3& angularRate, std::string& why) {
  Command c;
  c.velocity = velocity;
  c.angularRate = angularRate;
  if (!acceptable(c, "cmd_vel", why)) return false;
  velocity_ = velocity;
  angularRate_ = angularRate;
  pendingVelocity_ = true;
  return true;
}

bool CommandDesk::offerScale(double scale, std::string& why) {
  Command c;
  c.scale = scale;
  if (!acceptable(c, "scale", why)) return false;
  scale_ = scale;
  pendingScale_ = true;
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
