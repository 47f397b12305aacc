#pragma once
// The names of frames (the world frame, a namespace's prefix) and the one transform builder.

#include <set>
#include <string>
#include <vector>

#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>

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

/// Whether `frame` is `world`, a leading '/' of either ignored (tf1 wrote "/world").
bool isFrame(const std::string& frame, const std::string& world);

/**
 * The one check of the frame of a pose input (odometry): a message whose header.frame_id is not
 * the world frame is refused and counted, and the first refusal on each topic is one WARN naming
 * the topic, both frames and `consequence` (a TurtleBot's own odom starts each robot at 0, 0 of
 * a frame of its own: taken as world positions, it would place every robot wrongly, silently).
 */
class FrameGate {
 public:
  /// @param who the node's name in the WARN. @param consequence what happens while refused.
  FrameGate(std::string worldFrame, std::string who, std::string consequence);
  /// @return true if `frame` is the world frame; else counts it (and warns once per topic).
  bool admit(const std::string& frame, const std::string& topic);
  /// Messages refused so far, on every topic.
  long refused() const { return refused_; }
  const std::string& worldFrame() const { return world_; }
  /// " (N refused: not in the world frame 'W')" once any was refused, else "": for a waiting line.
  std::string refusedNote() const;

 private:
  std::string world_, who_, consequence_;
  long refused_ = 0;
  std::set<std::string> warned_;  // topics
};

/// The tf of a frame `child` at position (x, y, z) of header.frame_id, not rotated: the one
/// place that builds an agent's or a robot's transform.
geometry_msgs::TransformStamped frameAt(const std_msgs::Header& header, const std::string& child,
                                        const std::vector<double>& position);
/// frameAt written into `t`, every field: a transform reused step after step keeps its strings'
/// memory (the recorder's /tf of every agent at every step).
void setFrameAt(geometry_msgs::TransformStamped& t, const std_msgs::Header& header, const std::string& child,
                const std::vector<double>& position);

}  // namespace vf
