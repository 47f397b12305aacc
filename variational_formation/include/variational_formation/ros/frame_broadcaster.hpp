#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>

namespace vf {

/**
 * A lockstep agent's tf2 broadcaster: publishes on /tf, as tf2_ros::TransformBroadcaster does,
 * but only while /tf has a subscriber (rviz, a tf listener, rostopic). It counts the subscribers
 * from its connect and disconnect callbacks, which run on `nh`'s queue. Without one, an agent
 * manager's agents each built and published a TFMessage per step that nobody read: 15 % of a
 * 100-agent manager's time, most of it roscpp's topic lock shared with its network thread
 * (doc/benchmarks.md). A subscriber gets the frames sent after its connection is reported.
 */
class FrameBroadcaster {
 public:
  explicit FrameBroadcaster(ros::NodeHandle& nh);
  /// Whether /tf has a subscriber now.
  bool heard() const { return *listeners_ > 0; }
  /// Publishes frameAt(header, child, position) on /tf if heard(); builds nothing otherwise.
  void send(const std_msgs::Header& header, const std::string& child, const std::vector<double>& position);

 private:
  std::shared_ptr<std::atomic<int>> listeners_ = std::make_shared<std::atomic<int>>(0);
  ros::Publisher pub_;
};

}  // namespace vf
