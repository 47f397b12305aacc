#pragma once

#include <deque>
#include <vector>

#include <std_msgs/ColorRGBA.h>
#include <visualization_msgs/MarkerArray.h>

#include "variational_formation/AgentState.h"
#include "variational_formation/FormationStatus.h"
#include "variational_formation/core/monitor.hpp"

namespace vf {

using variational_formation::AgentState;
using variational_formation::FormationStatus;

/// Colour of agent i in rviz (a fixed palette, so screenshots can be checked).
std_msgs::ColorRGBA agentColour(int agent);

/// Status message of a snapshot.
FormationStatus toStatusMessage(const FormationSnapshot& snapshot);

/**
 * rviz markers of a snapshot in frame world: a sphere per agent, the edges coloured by their
 * distance error (green 0 to red >= 10% of d_ij), a trail per agent, the desired shape as a
 * faint ghost centred on the current centroid, and a text with step, energy and error.
 * @param trails per agent, the recent positions (oldest first).
 */
visualization_msgs::MarkerArray makeMarkers(const FormationSnapshot& snapshot, const Formation& formation,
                                            const std::vector<std::deque<Eigen::Vector3d>>& trails);

}  // namespace vf
