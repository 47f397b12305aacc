#include "variational_formation/ros/world_markers.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <geometry_msgs/Point.h>

#include "variational_formation/ros/markers.hpp"

namespace vf {

namespace {

using visualization_msgs::Marker;

constexpr double kContactHeight = 0.1;  // [m] where contact spheres float: above the bodies' tops

geometry_msgs::Point point(double x, double y, double z) {
  geometry_msgs::Point p;
  p.x = x;
  p.y = y;
  p.z = z;
  return p;
}

Marker marker(const std_msgs::Header& header, const std::string& ns, int id, int type) {
  Marker m;
  m.header = header;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = Marker::ADD;
  m.pose.orientation.w = 1.0;
  return m;
}

// A list of spheres of diameter `size` at (x, y) points; deleted when there are none (rviz warns
// about an empty list).
template <typename Points>
Marker spheres(const std_msgs::Header& header, const std::string& ns, const Points& points, double size,
               const std_msgs::ColorRGBA& c) {
  Marker m = marker(header, ns, 0, Marker::SPHERE_LIST);
  m.scale.x = m.scale.y = m.scale.z = size;
  m.color = c;
  for (const auto& p : points) m.points.push_back(point(p.x, p.y, kContactHeight));
  if (m.points.empty()) m.action = Marker::DELETE;
  return m;
}

}  // namespace

visualization_msgs::MarkerArray makeWorldMarkers(const MujocoWorld& world, const std_msgs::Header& header,
                                                 double agentRadius) {
  visualization_msgs::MarkerArray out;
  for (int i = 0; i < world.robotCount(); ++i) {
    const BodyOutline b = world.bodyOutline(i);
    Marker body = marker(header, "bodies", i, Marker::CYLINDER);
    body.pose.position = point(b.x, b.y, b.z);
    body.scale.x = body.scale.y = 2.0 * b.radius;
    body.scale.z = 2.0 * b.halfHeight;
    body.color = agentColour(i);  // solid: it shows through its agent's halo (AgentSpheres::Halos)
    out.markers.push_back(body);
    const PlanarPose p = world.pose(i);
    Marker heading = marker(header, "headings", i, Marker::ARROW);
    const double top = b.z + b.halfHeight + 0.01, reach = std::max(b.radius, agentRadius), length = 2.0 * reach;
    heading.points = {point(p.x, p.y, top),
                      point(p.x + length * std::cos(p.heading), p.y + length * std::sin(p.heading), top)};
    heading.scale.x = 0.2 * reach;  // shaft diameter
    heading.scale.y = 0.4 * reach;  // head diameter
    heading.scale.z = 0.5 * reach;  // head length
    heading.color = rgba(0.95, 0.95, 0.95, 1.0);
    out.markers.push_back(heading);
  }
  const std::vector<ObstacleGeom> obstacles = world.obstacleGeoms();
  for (std::size_t k = 0; k < obstacles.size(); ++k) {
    const ObstacleGeom& o = obstacles[k];
    static const int kTypes[] = {Marker::CYLINDER, Marker::CUBE, Marker::SPHERE, Marker::SPHERE};
    Marker m = marker(header, "obstacles", static_cast<int>(k), kTypes[static_cast<int>(o.type)]);
    m.pose.position = point(o.position[0], o.position[1], o.position[2]);
    m.pose.orientation.w = o.quaternion[0];
    m.pose.orientation.x = o.quaternion[1];
    m.pose.orientation.y = o.quaternion[2];
    m.pose.orientation.z = o.quaternion[3];
    // MuJoCo's sizes are half extents: radius and half height of a cylinder, radius of a sphere.
    switch (o.type) {
      case ObstacleGeom::Type::Cylinder:
        m.scale.x = m.scale.y = 2.0 * o.size[0];
        m.scale.z = 2.0 * o.size[1];
        break;
      case ObstacleGeom::Type::Box:
        m.scale.x = 2.0 * o.size[0];
        m.scale.y = 2.0 * o.size[1];
        m.scale.z = 2.0 * o.size[2];
        break;
      default:  // a sphere, or another shape drawn as the sphere of its first size
        m.scale.x = m.scale.y = m.scale.z = 2.0 * o.size[0];
        break;
    }
    m.color = rgba(0.6, 0.6, 0.6, 0.9);
    out.markers.push_back(m);
  }
  out.markers.push_back(spheres(header, "touching", world.touches(), 0.12, rgba(1.0, 0.1, 0.1, 1.0)));
  const std::vector<ContactEvent>& events = world.contacts().events();
  const std::vector<ContactEvent> drawn(events.end() - static_cast<long>(std::min(events.size(), kDrawnContacts)),
                                        events.end());
  out.markers.push_back(spheres(header, "contacts", drawn, 0.06, rgba(1.0, 0.55, 0.0, 0.9)));
  return out;
}

}  // namespace vf
