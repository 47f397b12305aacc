#include "variational_formation/ros/frame_broadcaster.hpp"

#include <tf2_msgs/TFMessage.h>

namespace vf {

FrameBroadcaster::FrameBroadcaster(ros::NodeHandle& nh) {
  const std::shared_ptr<std::atomic<int>> listeners = listeners_;
  pub_ = nh.advertise<tf2_msgs::TFMessage>(
      "/tf", 100, [listeners](const ros::SingleSubscriberPublisher&) { ++*listeners; },
      [listeners](const ros::SingleSubscriberPublisher&) { --*listeners; });
}

void FrameBroadcaster::send(const geometry_msgs::TransformStamped& frame) {
  if (!heard()) return;
  tf2_msgs::TFMessage message;
  message.transforms.push_back(frame);
  pub_.publish(message);
}

}  // namespace vf
