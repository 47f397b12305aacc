#include "variational_formation/ros/frame_broadcaster.hpp"

#include <tf2_msgs/TFMessage.h>

#include "variational_formation/ros/frames.hpp"

namespace vf {

FrameBroadcaster::FrameBroadcaster(ros::NodeHandle& nh) {
  const std::shared_ptr<std::atomic<int>> listeners = listeners_;
  pub_ = nh.advertise<tf2_msgs::TFMessage>(
      "/tf", 100, [listeners](const ros::SingleSubscriberPublisher&) { ++*listeners; },
      [listeners](const ros::SingleSubscriberPublisher&) { --*listeners; });
}

void FrameBroadcaster::send(const std_msgs::Header& header, const std::string& child,
                            const std::vector<double>& position) {
  if (!heard()) return;
  tf2_msgs::TFMessage message;
  message.transforms.push_back(frameAt(header, child, position));
  pub_.publish(message);
}

}  // namespace vf
