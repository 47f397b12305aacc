#pragma once

#include <functional>
#include <memory>
#include <string>

#include <actionlib/server/simple_action_server.h>
#include <geometry_msgs/PoseStamped.h>
#include <move_base_msgs/MoveBaseAction.h>
#include <ros/ros.h>

#include "variational_formation_core/manoeuvres/goal_steering.hpp"
#include "variational_formation_core/model/scenario.hpp"

namespace vf {

/**
 * Goals for the formation (doc/manoeuvres.md, "Goals"; doc/ros_api.md "monitor"): the action
 * server `move_to` (move_base_msgs/MoveBase) and the topic `move_base_simple/goal`
 * (geometry_msgs/PoseStamped, what rviz's "2D Nav Goal" publishes; a goal there becomes a goal of
 * the action, as move_base does), both relative to the formation's namespace. The steering is
 * core's GoalSteering; its commands go through the monitor's own command path (`offer`, the
 * CommandDesk with its limits), so they are step-stamped and recorded like any other command.
 */
class GoalServer {
 public:
  /// Offers a velocity command; false with `why` if the desk refuses it.
  using Offer = std::function<bool(const Vector3& velocity, const Vector3& angularRate, std::string& why)>;

  /// Reads ~goal_* from `pnh` (@throws InvalidInput), advertises in `nh`.
  GoalServer(ros::NodeHandle& nh, ros::NodeHandle& pnh, const Scenario& scenario, const std::string& worldFrame,
             Offer offer);
  /// Completed step `seen.step` at q (d x n) [m] (seen.pose is filled here), under the commands
  /// `inForce` (the desk's schedule).
  void onStep(GoalObservation seen, const Positions& q, const CommandSchedule& inForce, const ros::Time& stamp);
  /// The run is over: an active goal is aborted with `why`, new ones too.
  void end(const std::string& why);

 private:
  using Server = actionlib::SimpleActionServer<move_base_msgs::MoveBaseAction>;
  void onGoal();
  void onPreempt();
  void onTopicGoal(const geometry_msgs::PoseStamped::ConstPtr& goal);
  /// Offers the stop; false (aborting nothing itself) if the desk refuses it.
  void stopFormation();

  Positions desired_;
  long steps_;         // the scenario's (0: unbounded)
  double timeStep_;    // h [s]
  FormationPose now_;  // the centroid at lastStep_ (the start before any)
  std::string worldFrame_;
  Offer offer_;
  GoalSteering steering_;
  std::unique_ptr<Server> server_;
  ros::Subscriber topicSub_;
  ros::Publisher relay_;
  long lastStep_ = -1, feedbackEvery_ = 1, lastFeedback_ = -1;
  std::string ended_;  // why no goal is taken any more, empty while the run goes on
};

}  // namespace vf
