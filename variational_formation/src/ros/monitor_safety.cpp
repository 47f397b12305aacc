// The safety filter as the monitor sees it (MonitorNode, monitor_node.hpp; doc/ros_api.md
// "monitor"), in both modes: the closest pair and the constraints that bind at every status, the
// closest approach and filter_active_steps of the run, and blocked formations (core SafetyWatch,
// with the BlockedDetector simulate uses); the other formations' closest agent and the steps the
// filter bound on one (core ForeignWatch, doc/maths.md §10 "Other formations").
#include <cmath>
#include <limits>

#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation/ros/foreign_formations.hpp"
#include "variational_formation/ros/monitor_node.hpp"
#include "variational_formation/ros/parameters.hpp"

namespace vf {

void MonitorNode::setUpSafety(ros::NodeHandle& pnh, bool timed) {
  if (!scenario_.safety) {
    if (pnh.hasParam("blocked_after")) ROS_WARN("monitor: ~blocked_after is ignored: the scenario has no safety block");
    return;
  }
  const double blockedAfter = optionalParam(pnh, "blocked_after", scenario_.safety->blockedAfter);
  try {
    safety_ = std::make_unique<SafetyWatch>(scenario_, blockedAfter, timed);
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string("~") + e.what());  // the core names it without '~'
  }
  ROS_INFO("monitor: safety filter: r %g m; a formation whose filter binds while its distance error has not fallen "
           "for %g s is blocked, and the run ends there", scenario_.safety->radius, blockedAfter);
  // The other formations' agents as the agents hear them (avoid): the closest foreign pair.
  const ros::NodeHandle formation(ros::names::parentNamespace(pnh.getNamespace()));
  foreign_ = ForeignFormations::watch(formation, avoidParameter(pnh), scenario_.dimension);
  if (foreign_) foreignWatch_ = std::make_unique<ForeignWatch>(foreign_->agents());
}

void MonitorNode::noteSafety(int agent, const AgentState& msg) {
  if (safety_) safety_->note(agent, msg.step, static_cast<long>(msg.constraints_active));
  if (foreignWatch_ && foreignWatch_->note(msg.step, static_cast<long>(msg.foreign_constraints_active))) {
    ROS_WARN("monitor: step %ld: agent_%d's safety filter bound on an agent of another formation (avoid): from here "
             "the run depends on that formation's timing, and a lockstep run no longer equals simulate "
             "(foreign_constraint_steps in the result file)", static_cast<long>(msg.step), agent);
  }
}

bool MonitorNode::watchSafety(const FormationSnapshot& s, FormationStatus& status) {
  status.closest_foreign_approach = std::numeric_limits<double>::quiet_NaN();  // none heard (FormationStatus.msg)
  if (!safety_ || ended()) return false;
  const ClosestForeign foreign = foreignWatch_ ? foreignWatch_->observe(s.metrics.step, s.positions) : ClosestForeign();
  if (std::isfinite(foreign.distance)) {
    status.closest_foreign_approach = foreign.distance;
    status.closest_foreign_agents = {"agent_" + std::to_string(foreign.agent), foreign.foreign};
  }
  const bool wasBlocked = safety_->blocked();
  const bool blocked = safety_->observe(s.metrics.step, s.positions, s.metrics.maxDistanceError, s.congruent);
  status.min_separation = safety_->minSeparation();
  status.constraints_active = static_cast<uint32_t>(safety_->constraintsActive());
  if (status.min_separation < scenario_.safety->radius) {
    ROS_WARN_THROTTLE(1.0, "monitor: step %ld: agents %d and %d are %.4f m apart, closer than r = %g m",
                      s.metrics.step, safety_->lastPair().first, safety_->lastPair().second,
                      status.min_separation, scenario_.safety->radius);
  }
  if (!blocked || wasBlocked) return false;
  ROS_WARN("monitor: step %ld: the formation is %s (the safety filter binds and the distance error %.4g m has not "
           "fallen for ~blocked_after); ending the run",
           s.metrics.step, safety_->description().c_str(), s.metrics.maxDistanceError);
  return true;
}

std::string MonitorNode::safetyResultLines() const {
  return (safety_ ? safety_->resultLines() : std::string()) + (foreignWatch_ ? foreignWatch_->resultLines() : "");
}

std::string MonitorNode::blockedBy() const {
  return safety_ && safety_->blocked() ? safety_->description() : std::string();
}

}  // namespace vf
