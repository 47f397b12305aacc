// Goals for the formation (MonitorNode, monitor_node.hpp; GoalServer): their commands are offered
// to the monitor's CommandDesk like a cmd_vel, with its checks and limits, and issued as the mode
// issues any command (lockstep at the allowed step after the status, timed at once).
#include <algorithm>

#include "variational_formation/ros/monitor_node.hpp"

namespace vf {

void MonitorNode::setUpGoals(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  const std::string sender = nh.resolveName("move_to");
  goals_ = std::make_unique<GoalServer>(
      nh, pnh, scenario_, worldFrame_, [this, sender](const Vector3& v, const Vector3& w, std::string& why) {
        std::string note;
        if (ended()) {
          why = "the run is over";
          return false;
        }
        if (!desk_->offerVelocity(v, w, why, &note)) return false;
        warnCommand("move_to", sender, note);
        return true;
      });
}

void MonitorNode::steerGoal(const FormationSnapshot& s, bool constrained, const ros::Time& stamp) {
  GoalObservation seen;
  seen.step = s.metrics.step;
  seen.inShape = s.congruent;  // either hand: a goal steers the shape it holds
  seen.maxEdgeError = s.metrics.maxDistanceError;
  seen.constrained = constrained;
  // The desk issues at most one command per allowed step: past the newest issued one only.
  const long newest = desk_->issued().empty() ? -1 : desk_->issued().back().first;
  seen.applyStep = goalCommandsAt_ > std::max(newest, seen.step) ? goalCommandsAt_ : -1;
  goals_->onStep(seen, s.positions, desk_->schedule(), stamp);
}

}  // namespace vf
