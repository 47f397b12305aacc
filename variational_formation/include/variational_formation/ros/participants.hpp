#pragma once

#include <functional>
#include <string>
#include <vector>

#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>

#include "variational_formation_msgs/FormationCommand.h"
#include "variational_formation_core/manoeuvres/command_schedule.hpp"

#include "variational_formation_msgs/AgentState.h"
#include "variational_formation_msgs/RecallState.h"
#include "variational_formation_msgs/RunProgress.h"
#include "variational_formation_core/model/scenario.hpp"

namespace vf {

/// Full name of the node that owns agent `id` in the namespace of `nh` ("/formation/agent_3").
std::string agentNodeName(const ros::NodeHandle& nh, int id);

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

/// The command of a FormationCommand message (its step aside).
Command commandOf(const variational_formation_msgs::FormationCommand& message);

/// The tf of a frame `child` at position (x, y, z) of header.frame_id, not rotated: the one
/// place that builds an agent's or a robot's transform.
geometry_msgs::TransformStamped frameAt(const std_msgs::Header& header, const std::string& child,
                                        const std::vector<double>& position);

/**
 * loadScenario(path), parsed and checked once per content in this process: the agents of one
 * nodelet manager all load the same file, and its rigidity test costs O(n^3) (0.05 s at 200
 * agents). A file that changed is loaded again; an error is thrown as loadScenario throws it.
 */
Scenario sharedScenario(const std::string& path);

/// An agent's subscriptions (lockstep or timed): each neighbour's `agent_<j>/state` with queue
/// `stateQueue`, and the monitor's `progress`, with TCP_NODELAY, callbacks on nh's queue.
void subscribeToFormation(
    ros::NodeHandle& nh, const std::vector<int>& neighbours, uint32_t stateQueue,
    const std::function<void(int, const ros::MessageEvent<variational_formation_msgs::AgentState const>&)>& onState,
    const std::function<void(const ros::MessageEvent<variational_formation_msgs::RunProgress const>&)>& onProgress,
    std::vector<ros::Subscriber>& states, ros::Subscriber& progress);

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

/// Full name of a participant node given relative to the namespace of `nh` (e.g. "monitor").
std::string participantName(const ros::NodeHandle& nh, const std::string& relative);

/// Whether a message came from the node that owns its topic: the caller id of the message
/// event, compared with the owner's full node name. ROS 1 has no authentication, so this stops
/// mistakes and stray tools (a `rostopic pub`, a second formation), not a determined attacker.
template <class Event>
bool fromOwner(const Event& event, const std::string& owner) {
  return event.getPublisherName() == owner;
}

/**
 * The nodelet managers that agents of this formation may be loaded in (doc/distributed.md,
 * "Nodelets"): the private parameter `~agent_manager`, names relative to the namespace of `nh`,
 * separated by spaces; empty when every agent is a node of its own.
 */
std::vector<std::string> agentManagers(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);

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

/// What the master and the node's own XML-RPC port say about a node.
enum class Liveness { Alive, NotRegistered, NotAnswering, Busy };

/**
 * Asks the master for the node's URI and connects to it (0.5 s at most). A node that was killed
 * with SIGKILL stays registered, but its port refuses connections: NotAnswering. A stopped
 * (SIGSTOP) node still accepts connections: Alive. Busy when the master's call or the connection
 * times out instead of being refused (a master or manager busy registering a thousand agents):
 * not evidence of death. Blocks for at most about a second.
 */
Liveness nodeLiveness(const std::string& fullName);

const char* describe(Liveness liveness);

/// Creates the directory that will hold `path` (like mkdir -p). @throws InvalidInput naming
/// `parameter` when it cannot.
void createParentDirectory(const std::string& path, const std::string& parameter);

/// Seconds of wall time since `since` (for "waiting for ... for 5.0 s").
inline double secondsSince(const ros::WallTime& since) { return (ros::WallTime::now() - since).toSec(); }

}  // namespace vf
