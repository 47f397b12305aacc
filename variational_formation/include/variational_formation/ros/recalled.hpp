#pragma once
// Crash recovery's calls: where a restarting agent resumes.

#include <string>
#include <vector>

#include <ros/ros.h>

#include "variational_formation_msgs/RecallState.h"

namespace vf {

/// Where a restarting agent resumes: the newest of its states held by a neighbour or the monitor.
struct Recalled {
  long step = -1;  ///< the step found; -1 if nobody holds one beyond step 0
  variational_formation_msgs::RecallState::Response found;
  std::string from;  ///< the holder's node name
};

/**
 * Asks agent `id`'s neighbours, then the monitor (the fallback: it holds everyone's newest
 * state), for their `~recall` of it, at once and for 2 s at most, and picks the answer with
 * protocol::chooseAgentResume. Touches nothing that callbacks change.
 */
Recalled recallNewest(const ros::NodeHandle& nh, int id, const std::vector<int>& neighbours, const std::string& monitor);

}  // namespace vf
