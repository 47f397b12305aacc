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

/// Radius of the agents' spheres [m]: a tenth of the shortest desired edge (1 m without edges),
/// at least 5 cm; the other markers' sizes follow it.
double agentSphereRadius(const Formation& formation);

/// Status message of a snapshot.
FormationStatus toStatusMessage(const FormationSnapshot& snapshot);

/// Which markers a step's array holds: all of them, or only those that move with the agents at
/// every step (agents, edges, text, command arrow). rviz keeps drawing the trails and the ghost of
/// the last array that held them (a marker stays until replaced or deleted).
enum class MarkerParts { All, Moving };

/// How the agents' spheres are drawn: solid, or, in a robot run (the monitor's ~measure_robots),
/// as translucent halos (opacity kHaloAlpha) through which each robot's body and heading, drawn
/// solid by its world (world_markers.hpp), show: a sphere is a tenth of the shortest desired
/// distance in radius, 0.3 m on the side-3 hexagon, and a TurtleBot3 Burger's body 0.105 m.
enum class AgentSpheres { Solid, Halos };
constexpr float kHaloAlpha = 0.35f;

/// Simulated seconds between two arrays with every marker, at least: 25 a simulated second, as
/// often as rviz redraws (doc/benchmarks.md, "Recording and pacing").
constexpr double kAllMarkersPeriod = 0.04;

/// Simulated seconds between two marker arrays at the default `~marker_every` (0): 50 arrays a
/// simulated second, about as often as a screen shows a picture (doc/benchmarks.md, "Markers at a
/// simulated-time rate").
constexpr double kMarkerPeriod = 0.02;

/**
 * Steps between two marker arrays, the monitor's and the recorder's `~marker_every` made one
 * number: `requested` >= 1 as it is; 0 (the default) ceil(kMarkerPeriod / h), at least 1.
 * @param timeStep h [s] (> 0).
 * @throws InvalidInput ("~marker_every: ...") for a negative `requested`.
 */
long markerEvery(long requested, double timeStep);

/**
 * Steps between two arrays with every marker (the trails and the ghost, the bulk of an array):
 * max(stride, ceil(kAllMarkersPeriod / h)), so that an array with trails comes about as often as
 * the trails gain a position, and never much more often than rviz redraws.
 * @param trailStride Trails::stride(). @param timeStep h [s] (> 0).
 */
long allMarkersEvery(int trailStride, double timeStep);

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
 * @param parts MarkerParts::Moving leaves out the trails and the ghost (ns `trails` and
 * `desired_shape`).
 * @param spheres AgentSpheres::Halos: the agents' colours at opacity kHaloAlpha (a robot run).
 */
visualization_msgs::MarkerArray makeMarkers(const FormationSnapshot& snapshot, const Formation& formation,
                                            const Trails& trails, const CommandSchedule* schedule = nullptr,
                                            double timeStep = 0.0, MarkerParts parts = MarkerParts::All,
                                            AgentSpheres spheres = AgentSpheres::Solid);

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
