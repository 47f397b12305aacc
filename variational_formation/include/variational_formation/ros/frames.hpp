#pragma once
// The names of frames (the world frame, a namespace's prefix) and the one transform builder.

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>
#include <tf2_msgs/TFMessage.h>

namespace vf {

/// The prefix of frame names in the namespace of `nh`: "formation/" in /formation, "" in the
/// root namespace (which a nodelet's handle spells "" and a node's "/").
std::string framePrefix(const ros::NodeHandle& nh);

/**
 * The fixed frame of states, poses, markers, odometry and tf: the parameter world_frame, looked
 * up from the node's private namespace upwards (~world_frame, then <namespace>/world_frame, ...,
 * as searchParam does), default "world".
 * @throws InvalidInput on an empty name or one with spaces.
 */
std::string worldFrame(const ros::NodeHandle& pnh);

/// The tf of a frame `child` at position (x, y, z) of header.frame_id, not rotated: the one
/// place that builds an agent's or a robot's transform.
geometry_msgs::TransformStamped frameAt(const std_msgs::Header& header, const std::string& child,
                                        const std::vector<double>& position);

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
  /// Whether /tf has a subscriber now: only then is send() worth a transform.
  bool heard() const { return *listeners_ > 0; }
  /// Publishes `frame` on /tf if heard().
  void send(const geometry_msgs::TransformStamped& frame);

 private:
  std::shared_ptr<std::atomic<int>> listeners_ = std::make_shared<std::atomic<int>>(0);
  ros::Publisher pub_;
};

}  // namespace vf
