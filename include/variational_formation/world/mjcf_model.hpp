#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "variational_formation/core/hand_point.hpp"
#include "variational_formation/core/scenario.hpp"
#include "variational_formation/world/world_settings.hpp"

namespace vf {

/**
 * A static obstacle of the world: a vertical cylinder standing on the floor, geom
 * `obstacle_<k>`. This is the seam for the scenario's `obstacles:` block (the collision-avoidance
 * issue): once the core loader reads it, its shapes become these, and the world counts contacts
 * with them as robot-obstacle contacts.
 */
struct StaticObstacle {
  double x = 0.0, y = 0.0;  ///< centre on the floor [m], world frame
  double radius = 0.1;      ///< [m] > 0
  double height = 0.3;      ///< [m] > 0
};

/**
 * The start pose of robot i [m, m, rad], as robot_sim starts it: a holonomic base at the
 * scenario's initial position with heading 0; a unicycle's axle hand_offset behind the initial
 * position (its hand point there), at the scenario's initial_heading if the scenario gives
 * headings, else at drawInitialHeading(headingSeed, i).
 * @throws InvalidInput "dimension: ..." for a scenario that is not planar.
 */
std::vector<PlanarPose> worldStartPoses(const Scenario& scenario, const WorldSettings& settings,
                                        std::uint64_t headingSeed);

/**
 * The MJCF text of a world: a floor, one robot per start pose (bodies `robot_<i>`, with the
 * joints and velocity actuators that MujocoWorld drives, see mujoco_world.hpp for the names), and
 * the obstacles. Validates the settings first. @throws InvalidInput naming a bad setting, a
 * non-finite pose or a bad obstacle.
 */
std::string buildWorldMjcf(const WorldSettings& settings, const std::vector<PlanarPose>& starts,
                           const std::vector<StaticObstacle>& obstacles = {});

}  // namespace vf
