#pragma once
// The names of frames (the world frame, a namespace's prefix) and the one transform builder.

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


/// The tf of a frame `child` at position (x, y, z) of header.frame_id, not rotated: the one
/// place that builds an agent's or a robot's transform.
geometry_msgs::TransformStamped frameAt(const std_msgs::Header& header, const std::string& child,
                                        const std::vector<double>& position);
/// frameAt written into `t`, every field: a transform reused step after step keeps its strings'
/// memory (the recorder's /tf of every agent at every step).
void setFrameAt(geometry_msgs::TransformStamped& t, const std_msgs::Header& header, const std::string& child,
                const std::vector<double>& position);

}  // namespace vf
