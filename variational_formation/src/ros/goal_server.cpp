#include "variational_formation/ros/goal_server.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation/ros/frames.hpp"
#include "variational_formation/ros/parameters.hpp"

namespace vf {

namespace {

GoalSettings goalSettings(ros::NodeHandle& pnh) {
  GoalSettings s;
  s.maxSpeed = optionalParam(pnh, "goal_max_speed", s.maxSpeed);
  s.maxTurnRate = optionalParam(pnh, "goal_max_turn_rate", s.maxTurnRate);
  s.gain = optionalParam(pnh, "goal_gain", s.gain);
  s.positionTolerance = optionalParam(pnh, "goal_tolerance", s.positionTolerance);
  s.yawTolerance = optionalParam(pnh, "goal_yaw_tolerance", s.yawTolerance);
  s.patience = optionalParam(pnh, "goal_patience", s.patience);
  s.period = optionalParam(pnh, "goal_period", s.period);
  validateGoalSettings(s);
  return s;
}

}  // namespace

GoalServer::GoalServer(ros::NodeHandle& nh, ros::NodeHandle& pnh, const Scenario& scenario,
                       const std::string& worldFrame, Offer offer)
    : desired_(scenario.desiredPositions),
      steps_(scenario.steps),
      timeStep_(scenario.timeStep),
      worldFrame_(worldFrame),
      offer_(std::move(offer)),
      steering_(goalSettings(pnh), scenario.timeStep, scenario.dampingGain),
      feedbackEvery_(std::max(1L, std::lround(0.1 / scenario.timeStep))) {
  server_ = std::make_unique<Server>(nh, "move_to", false);
  server_->registerGoalCallback([this] { onGoal(); });
  server_->registerPreemptCallback([this] { onPreempt(); });
  now_.position = scenario.initialPositions.topRows<2>().rowwise().mean();
  server_->start();
  // rviz's 2D Nav Goal: remapped to /move_base_simple/goal by formation.launch.
  relay_ = nh.advertise<move_base_msgs::MoveBaseActionGoal>("move_to/goal", 10);
  topicSub_ = nh.subscribe("move_base_simple/goal", 10, &GoalServer::onTopicGoal, this);
}

void GoalServer::onTopicGoal(const geometry_msgs::PoseStamped::ConstPtr& goal) {
  // As move_base does: the pose becomes a goal of the action (pre-empting the active one).
  move_base_msgs::MoveBaseActionGoal g;
  g.header.stamp = ros::Time::now();
  g.goal.target_pose = *goal;
  relay_.publish(g);
}

void GoalServer::onGoal() {
  const auto goal = server_->acceptNewGoal();  // the active one, if any, ends as pre-empted
  if (!goal) return;
  move_base_msgs::MoveBaseResult result;
  if (!ended_.empty()) {
    server_->setAborted(result, ended_);
    return;
  }
  const geometry_msgs::PoseStamped& t = goal->target_pose;
  try {
    if (!t.header.frame_id.empty() && !isFrame(t.header.frame_id, worldFrame_)) {
      throw InvalidInput("goal.target_pose.header.frame_id: must be the formation's frame '" + worldFrame_ +
                         "' (or empty), got '" + t.header.frame_id + "'");
    }
    const GoalPose pose = goalPose(t.pose.position.x, t.pose.position.y, t.pose.orientation.x, t.pose.orientation.y,
                                   t.pose.orientation.z, t.pose.orientation.w, "goal.target_pose.pose");
    const double left = steps_ > 0 ? static_cast<double>(steps_ - std::max(lastStep_, 0L)) * timeStep_
                                   : std::numeric_limits<double>::infinity();
    steering_.checkReachable(pose, now_, left, "goal.target_pose.pose.position");
    steering_.start(pose, lastStep_ + 1);
    ROS_INFO("monitor: goal (%g, %g) m, yaw %g rad: steering the centroid there", pose.position.x(),
             pose.position.y(), pose.yaw);
  } catch (const InvalidInput& e) {
    ROS_WARN("monitor: goal refused: %s", e.what());
    if (steering_.stop()) stopFormation();
    server_->setAborted(result, e.what());
  }
}

void GoalServer::onPreempt() {
  if (server_->isNewGoalAvailable()) return;  // onGoal follows and replaces it
  if (steering_.stop()) stopFormation();
  ROS_INFO("monitor: goal cancelled; the formation stops");
  server_->setPreempted(move_base_msgs::MoveBaseResult(), "cancelled");
}

void GoalServer::stopFormation() {
  std::string why;
  if (!offer_(Vector3::Zero(), Vector3::Zero(), why)) ROS_WARN("monitor: the stop was refused: %s", why.c_str());
}

void GoalServer::onStep(GoalObservation seen, const Positions& q, const CommandSchedule& inForce,
                        const ros::Time& stamp) {
  const long step = lastStep_ = seen.step;
  now_.position = q.topRows<2>().rowwise().mean();
  if (!steering_.active() || !server_->isActive()) return;
  seen.pose = formationPose(q, desired_);
  const FormationPose& pose = seen.pose;
  const SteeringStep s = steering_.update(seen, inForce);
  if (s.command) {
    std::string why;
    if (!offer_(s.velocity, s.angularRate, why)) {
      steering_.stop();
      server_->setAborted(move_base_msgs::MoveBaseResult(), "the command was refused: " + why);
      ROS_WARN("monitor: goal aborted: the command was refused: %s", why.c_str());
      return;
    }
  }
  if (s.state == SteeringStep::State::Succeeded) {
    ROS_INFO("monitor: goal reached at step %ld: %.3f m and %.3f rad from it", step, s.distance, s.yawError);
    server_->setSucceeded(move_base_msgs::MoveBaseResult(), "reached");
  } else if (s.state == SteeringStep::State::Aborted) {
    ROS_WARN("monitor: goal aborted at step %ld: %s", step, s.reason.c_str());
    server_->setAborted(move_base_msgs::MoveBaseResult(), s.reason);
  } else if (step - lastFeedback_ >= feedbackEvery_) {
    // The centroid and heading; the distance left is |goal - base_position|.
    lastFeedback_ = step;
    move_base_msgs::MoveBaseFeedback f;
    f.base_position.header.stamp = stamp;
    f.base_position.header.frame_id = worldFrame_;
    f.base_position.pose.position.x = pose.position.x();
    f.base_position.pose.position.y = pose.position.y();
    f.base_position.pose.orientation.z = std::sin(pose.yaw / 2);
    f.base_position.pose.orientation.w = std::cos(pose.yaw / 2);
    server_->publishFeedback(f);
    ROS_INFO_THROTTLE(1.0, "monitor: goal: %.3f m and %.3f rad left", s.distance, s.yawError);
  }
}

void GoalServer::end(const std::string& why) {
  ended_ = why;
  if (steering_.stop() && server_->isActive()) server_->setAborted(move_base_msgs::MoveBaseResult(), why);
}

}  // namespace vf
