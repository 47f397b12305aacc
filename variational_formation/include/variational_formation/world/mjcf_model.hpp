#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "variational_formation_core/robots/unicycle_command.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation/world/world_settings.hpp"

namespace vf {

/**
 * A static obstacle of the world, standing on the floor: geom `obstacle_<k>`, a vertical
 * cylinder or a box with its sides along the world's axes. The world counts contacts with it as
 * robot-obstacle contacts. worldObstacles makes them from the scenario's `obstacles:` block.
 */
struct StaticObstacle {
  enum class Shape { Cylinder, Box };
  double x = 0.0, y = 0.0;  ///< centre on the floor [m], world frame
  double radius = 0.1;      ///< cylinder [m] > 0
  double height = 0.3;      ///< [m] > 0
  Shape shape = Shape::Cylinder;
  double halfX = 0.0, halfY = 0.0;  ///< box: half its extent along the world's x and y [m] > 0
};

/**
 * The scenario's `obstacles:` as static geoms of its height [m] (doc/robots.md, "Obstacles"): a
 * disc becomes a cylinder, an axis-aligned box a box. Both are what the safety filter keeps its
 * agents from; a disc of radius 0 or a box that is flat along an axis (a point or a wall line to
 * the filter) becomes a post or a wall kMinObstacleHalfWidth thick on each side.
 * @throws InvalidInput "dimension: ..." for a scenario that is not planar.
 */
std::vector<StaticObstacle> worldObstacles(const Scenario& scenario, double height = 0.3);
/// The half width [m] a point or a flat box of the scenario gets in the world (MuJoCo's geoms need one).
constexpr double kMinObstacleHalfWidth = 0.005;

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
