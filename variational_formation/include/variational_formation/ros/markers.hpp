#pragma once

#include <std_msgs/ColorRGBA.h>
#include <visualization_msgs/MarkerArray.h>

#include "variational_formation_msgs/AgentState.h"
#include "variational_formation_msgs/FormationStatus.h"
#include "variational_formation_core/agents/formation_monitor.hpp"
#include "variational_formation_core/safety/safety_settings.hpp"
#include "variational_formation_core/manoeuvres/commanded_frame.hpp"
#include "variational_formation/ros/trails.hpp"

namespace vf {

using variational_formation_msgs::AgentState;
using variational_formation_msgs::FormationStatus;

/// An rviz colour from its red, green, blue and opacity in [0, 1].
std_msgs::ColorRGBA rgba(double r, double g, double b, double a);

/// Colour of agent i in rviz (a fixed palette, so screenshots can be checked).
std_msgs::ColorRGBA agentColour(int agent);

/// Status message of a snapshot.
FormationStatus toStatusMessage(const FormationSnapshot& snapshot);

/**
 * rviz markers of a snapshot in frame world, a fixed handful of markers whatever the agent count:
 * the agents (ns `agents`, one SPHERE_LIST: a sphere per agent at q_i, in agentColour(i)), the
 * edges coloured by their distance error (ns `edges`, one LINE_LIST: 2 points per edge, tail
 * then head, green 0 to red >= 10% of d_ij), the trails (ns `trails`, one LINE_LIST: per agent,
 * segments through its kept positions and on to q_i, in its colour), the desired shape as a faint
 * ghost centred on the current centroid (ns `desired_shape`: edges, id 0, and agents, id 1), and
 * a text with step, energy and error. Under a commanded motion (`schedule`), the ghost is turned
 * and scaled as the commands have turned and scaled the shape by this step (commandedFrame), and
 * an arrow from the centroid shows v*.
 * @param trails the agents' recent positions (one trail per agent of the formation).
 * @param schedule the commands the agents apply, or nullptr. @param timeStep h [s].
 */
visualization_msgs::MarkerArray makeMarkers(const FormationSnapshot& snapshot, const Formation& formation,
                                            const Trails& trails, const CommandSchedule* schedule = nullptr,
                                            double timeStep = 0.0);

/**
 * The safety filter's markers (a scenario with `safety:`), appended to `out`: per agent its safety
 * disc of radius r/2 (a flat cylinder in 2D, a ball in 3D), coloured by how near its closest
 * neighbour is (green at R or farther, yellow at (r + R)/2, red at r or nearer; the neighbours
 * from a SpatialGrid, O(n)), and the obstacles (discs and boxes: flat cylinders and boxes in 2D,
 * spheres and cubes in 3D), grey.
 */
void addSafetyMarkers(const FormationSnapshot& snapshot, const SafetySettings& safety,
                      const std::vector<Obstacle>& obstacles, visualization_msgs::MarkerArray& out);

}  // namespace vf
