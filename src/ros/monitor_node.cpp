#include "variational_formation/ros/monitor_node.hpp"

#include <ros/callback_queue.h>

#include "variational_formation/FormationStatus.h"
#include "variational_formation/ros/markers.hpp"
#include "variational_formation/ros/parameters.hpp"

namespace vf {

MonitorNode::MonitorNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  const std::string path = requiredParam<std::string>(pnh, "scenario");
  trailLength_ = optionalParam(pnh, "trail_length", 100);
  statusSubscribers_ = optionalParam(pnh, "status_subscribers", 0);
  markerSubscribers_ = optionalParam(pnh, "marker_subscribers", 0);
  if (trailLength_ < 2) throw InvalidInput("~trail_length: must be >= 2");
  if (statusSubscribers_ < 0 || markerSubscribers_ < 0) {
    throw InvalidInput("~status_subscribers/~marker_subscribers: must be >= 0");
  }
  monitor_ = std::make_unique<FormationMonitor>(loadScenario(path));
  const int n = monitor_->formation().agentCount();
  trails_.resize(static_cast<std::size_t>(n));
  statusPub_ = nh.advertise<FormationStatus>("status", 1000);
  markersPub_ = nh.advertise<visualization_msgs::MarkerArray>("markers", 1000);
  for (int i = 0; i < n; ++i) {
    subs_.push_back(nh.subscribe("agent_" + std::to_string(i) + "/state", 1000,
                                             boost::function<void(const AgentState::ConstPtr&)>(
                                                 [this, i](const AgentState::ConstPtr& m) { onState(i, m); }),
                                 ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
  }
  ROS_INFO("monitor: scenario '%s' (%s), %d agents, %zu edges, %ld steps", monitor_->scenario().name.c_str(),
           path.c_str(), n, monitor_->formation().edges().size(), monitor_->scenario().steps);
}

void MonitorNode::onState(int expectedSender, const AgentState::ConstPtr& msg) {
  try {
    if (static_cast<int>(msg->id) == expectedSender &&
        monitor_->add(expectedSender, msg->step, msg->position, msg->previous_position)) {
      return;
    }
    // A state already completed (a latched repeat) is no error.
    if (static_cast<int>(msg->id) == expectedSender && msg->step < monitor_->nextStep()) return;
    ++dropped_;
    ROS_WARN_THROTTLE(1.0, "monitor: dropped a malformed state on agent_%d's topic (id %u, step %ld); %ld so far",
                      expectedSender, msg->id, static_cast<long>(msg->step), dropped_);
  } catch (const std::exception& e) {
    ++dropped_;
    ROS_WARN_THROTTLE(1.0, "monitor: dropped a state: %s", e.what());
  }
}

void MonitorNode::publishCompleted() {
  for (const FormationSnapshot& s : monitor_->takeCompleted()) {
    if (s.metrics.step == 0) firstStepAt_ = ros::WallTime::now();
    for (int i = 0; i < monitor_->formation().agentCount(); ++i) {
      auto& trail = trails_[static_cast<std::size_t>(i)];
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      p.head(s.positions.rows()) = s.positions.col(i);
      trail.push_back(p);
      if (static_cast<int>(trail.size()) > trailLength_) trail.pop_front();
    }
    statusPub_.publish(toStatusMessage(s));
    markersPub_.publish(makeMarkers(s, monitor_->formation(), trails_));
    if (s.converged && reportedConvergence_ != s.convergedStep) {
      ROS_INFO("monitor: congruent with the desired shape since step %ld (t = %.3f s)", s.convergedStep,
               s.convergedStep * monitor_->scenario().timeStep);
      reportedConvergence_ = s.convergedStep;
    } else if (!s.converged && reportedConvergence_ >= 0) {
      ROS_INFO("monitor: left the desired shape at step %ld", s.metrics.step);
      reportedConvergence_ = -2;
    }
  }
}

void MonitorNode::run() {
  auto* queue = ros::getGlobalCallbackQueue();
  // Hold every step until the recorder and rviz (if any) listen, so that they miss nothing.
  while (ros::ok() && (statusPub_.getNumSubscribers() < static_cast<unsigned>(statusSubscribers_) ||
                       markersPub_.getNumSubscribers() < static_cast<unsigned>(markerSubscribers_))) {
    queue->callAvailable(ros::WallDuration(0.005));
  }
  const long last = monitor_->scenario().steps;
  while (ros::ok() && (last == 0 || monitor_->nextStep() <= last)) {
    queue->callAvailable(ros::WallDuration(0.1));  // returns as soon as a state arrives
    publishCompleted();
  }
  if (!ros::ok()) return;
  const double seconds = (ros::WallTime::now() - firstStepAt_).toSec();
  const double h = monitor_->scenario().timeStep;
  ROS_INFO("monitor: %ld steps in %.3f s: %.0f steps/s, real-time factor %.1f at h = %g; %s; %ld dropped",
           last, seconds, last / seconds, last * h / seconds, h,
           reportedConvergence_ >= 0 ? ("converged at step " + std::to_string(reportedConvergence_)).c_str()
                                     : "not converged",
           dropped_);
  // Let the recorder take the last messages before roslaunch tears the run down.
  ros::WallDuration(1.0).sleep();
}

}  // namespace vf
