#pragma once

#include <std_msgs/Header.h>
#include <visualization_msgs/MarkerArray.h>

#include "variational_formation/world/mujoco_world.hpp"

namespace vf {

/// At most this many past contacts are drawn (the newest ones).
constexpr std::size_t kDrawnContacts = 200;

/**
 * rviz markers of a MuJoCo world (doc/robots.md, "Markers"), in the header's frame and stamp:
 * - `bodies`: each robot's body as a cylinder in its agent's colour (agentColour), solid: the
 *   monitor of a robot run draws the agents as translucent halos (AgentSpheres::Halos) round them;
 * - `headings`: a white arrow per robot from its origin (a unicycle's axle) along its heading, just
 *   above the body's top, 2 max(body radius, `agentRadius`) long: it reaches out of its agent's
 *   halo, so the heading shows at the formation's scale (shaft and head in proportion);
 * - `obstacles`: the model's obstacle geoms, grey;
 * - `touching`: a red sphere where two participants touch now (deleted while none do);
 * - `contacts`: a small orange sphere where each contact so far began (the newest kDrawnContacts).
 */
/// @param agentRadius the monitor's agent spheres' radius [m] (agentSphereRadius), 0 if none.
visualization_msgs::MarkerArray makeWorldMarkers(const MujocoWorld& world, const std_msgs::Header& header,
                                                 double agentRadius = 0.0);

}  // namespace vf
