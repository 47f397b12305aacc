#pragma once
// Whether a node is alive, asked of the master and of the node's own port.

#include <string>

#include <ros/ros.h>

namespace vf {

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

/// Seconds of wall time since `since` (for "waiting for ... for 5.0 s").
inline double secondsSince(const ros::WallTime& since) { return (ros::WallTime::now() - since).toSec(); }

}  // namespace vf
