#pragma once
// Who is who in a formation: participants' full node names, the agents' nodelet managers, and
// whether a message came from the node that owns its topic.

#include <string>
#include <vector>

#include <ros/ros.h>

namespace vf {

/// Full name of the node that owns agent `id` in the namespace of `nh` ("/formation/agent_3").
std::string agentNodeName(const ros::NodeHandle& nh, int id);

/// Full name of a participant node given relative to the namespace of `nh` (e.g. "monitor").
std::string participantName(const ros::NodeHandle& nh, const std::string& relative);

/**
 * The nodelet managers that agents of this formation may be loaded in (doc/distributed.md,
 * "Nodelets"): the private parameter `~agent_manager`, names relative to the namespace of `nh`,
 * separated by spaces; empty when every agent is a node of its own.
 */
std::vector<std::string> agentManagers(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);

/// Whether a message came from the node that owns its topic: the caller id of the message
/// event, compared with the owner's full node name. ROS 1 has no authentication, so this stops
/// mistakes and stray tools (a `rostopic pub`, a second formation), not a determined attacker.
template <class Event>
bool fromOwner(const Event& event, const std::string& owner) {
  return event.getPublisherName() == owner;
}

/// fromOwner for an agent's state: a nodelet's messages carry its manager's name as caller id,
/// so a state from one of `managers` is accepted too.
template <class Event>
bool fromAgent(const Event& event, const std::string& owner, const std::vector<std::string>& managers) {
  if (fromOwner(event, owner)) return true;
  for (const std::string& m : managers) {
    if (event.getPublisherName() == m) return true;
  }
  return false;
}

}  // namespace vf
