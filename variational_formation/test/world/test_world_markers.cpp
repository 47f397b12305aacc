// The MuJoCo world's rviz markers (ros/world_markers.hpp) on a shipped MujocoWorld: the bodies
// where the world has them, the headings along the bodies' poses, the obstacles at their size,
// and the contacts where the bodies touch. No master: the markers are a function of the world.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

#include "variational_formation/ros/markers.hpp"
#include "variational_formation/ros/world_markers.hpp"
#include "variational_formation/world/mjcf_model.hpp"

namespace vf {
namespace {

using visualization_msgs::Marker;

std::map<std::string, std::vector<Marker>> byNamespace(const visualization_msgs::MarkerArray& array) {
  std::map<std::string, std::vector<Marker>> out;
  for (const Marker& m : array.markers) out[m.ns].push_back(m);
  return out;
}

TEST(WorldMarkers, ShowBodiesHeadingsObstaclesAndContacts) {
  WorldSettings s;
  s.kinematics = WorldKinematics::Unicycle;
  StaticObstacle box;  // a wall across robot_1's way, 0.6 m ahead of it
  box.shape = StaticObstacle::Shape::Box;
  box.x = 2.0;
  box.y = 0.8;
  box.halfX = 0.5;
  box.halfY = 0.1;
  MujocoWorld world(buildWorldMjcf(s, {{0.0, 0.0, 0.3}, {2.0, 0.0, 0.5 * M_PI}}, {box}), "test", 2, s);
  std_msgs::Header header;
  header.frame_id = "map";
  header.stamp = ros::Time(12.5);

  auto markers = byNamespace(makeWorldMarkers(world, header));
  ASSERT_EQ(markers["bodies"].size(), 2u);
  ASSERT_EQ(markers["headings"].size(), 2u);
  for (int i = 0; i < 2; ++i) {
    const Marker& body = markers["bodies"][static_cast<std::size_t>(i)];
    const BodyOutline b = world.bodyOutline(i);
    EXPECT_EQ(body.type, Marker::CYLINDER);
    EXPECT_EQ(body.id, i);
    EXPECT_EQ(body.header.frame_id, "map");
    EXPECT_EQ(body.header.stamp, ros::Time(12.5));
    EXPECT_DOUBLE_EQ(body.pose.position.x, b.x);
    EXPECT_DOUBLE_EQ(body.pose.position.y, b.y);
    EXPECT_DOUBLE_EQ(body.scale.x, 2.0 * s.bodyRadius);
    EXPECT_EQ(body.color.r, agentColour(i).r);
    EXPECT_EQ(body.color.g, agentColour(i).g);
    EXPECT_EQ(body.color.a, 1.0f);  // solid, seen through its agent's halo (was 0.5: hidden in the sphere)
    // The arrow runs from the axle along the heading.
    const Marker& arrow = markers["headings"][static_cast<std::size_t>(i)];
    const PlanarPose p = world.pose(i);
    ASSERT_EQ(arrow.points.size(), 2u);
    EXPECT_DOUBLE_EQ(arrow.points[0].x, p.x);
    EXPECT_DOUBLE_EQ(arrow.points[0].y, p.y);
    EXPECT_NEAR(std::atan2(arrow.points[1].y - p.y, arrow.points[1].x - p.x), p.heading, 1e-12);
    // On top of the body, where nothing hides it, two body radii long without agent spheres.
    EXPECT_GT(arrow.points[0].z, body.pose.position.z + 0.5 * body.scale.z);
    EXPECT_EQ(arrow.points[1].z, arrow.points[0].z);
    EXPECT_NEAR(std::hypot(arrow.points[1].x - p.x, arrow.points[1].y - p.y), 2.0 * s.bodyRadius, 1e-12);
  }
  // Beside agent spheres of radius 0.3 m (the side-3 hexagon's), the arrows reach 0.6 m: out of
  // the sphere round the robot, as thick as the sphere's scale asks.
  auto beside = byNamespace(makeWorldMarkers(world, header, 0.3));
  ASSERT_EQ(beside["headings"].size(), 2u);
  for (const Marker& arrow : beside["headings"]) {
    EXPECT_NEAR(std::hypot(arrow.points[1].x - arrow.points[0].x, arrow.points[1].y - arrow.points[0].y), 0.6, 1e-12);
    EXPECT_NEAR(arrow.scale.x, 0.06, 1e-12);
  }
  // The unicycle's body sits 0.4 radius behind its axle, as the model builds it.
  EXPECT_NEAR(markers["bodies"][0].pose.position.x, -0.4 * s.bodyRadius * std::cos(0.3), 1e-9);
  ASSERT_EQ(markers["obstacles"].size(), 1u);
  const Marker& wall = markers["obstacles"][0];
  EXPECT_EQ(wall.type, Marker::CUBE);
  EXPECT_DOUBLE_EQ(wall.pose.position.x, 2.0);
  EXPECT_DOUBLE_EQ(wall.scale.x, 1.0);
  EXPECT_DOUBLE_EQ(wall.scale.y, 0.2);
  // Nothing touches yet: the contact markers are deleted.
  ASSERT_EQ(markers["touching"].size(), 1u);
  EXPECT_EQ(markers["touching"][0].action, Marker::DELETE);
  EXPECT_EQ(markers["contacts"][0].action, Marker::DELETE);

  // robot_1 drives into the wall: one sphere where it touches now, one where the contact began.
  while (world.time() < 2.5) {
    world.setCommand(1, 0.5, 0.0, 0.0);
    world.step();
  }
  ASSERT_EQ(world.contacts().count(), 1);
  markers = byNamespace(makeWorldMarkers(world, header));
  const Marker& touching = markers["touching"][0];
  EXPECT_EQ(touching.action, Marker::ADD);
  ASSERT_EQ(touching.points.size(), 1u);
  EXPECT_NEAR(touching.points[0].y, box.y - box.halfY, 0.01);  // on the wall's near face
  EXPECT_NEAR(touching.points[0].x, 2.0, 0.05);
  const Marker& began = markers["contacts"][0];
  ASSERT_EQ(began.points.size(), 1u);
  EXPECT_NEAR(began.points[0].y, box.y - box.halfY, 0.01);
}

}  // namespace
}  // namespace vf
