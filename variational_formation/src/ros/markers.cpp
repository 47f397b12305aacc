#include "variational_formation/ros/markers.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/spatial_grid.hpp"

namespace vf {

std_msgs::ColorRGBA rgba(double r, double g, double b, double a) {
  std_msgs::ColorRGBA c;
  c.r = static_cast<float>(r);
  c.g = static_cast<float>(g);
  c.b = static_cast<float>(b);
  c.a = static_cast<float>(a);
  return c;
}

namespace {

geometry_msgs::Point point(const Eigen::Vector3d& p) {
  geometry_msgs::Point q;
  q.x = p.x();
  q.y = p.y();
  q.z = p.z();
  return q;
}

/// q_i in 3D (z = 0 in 2D), element by element: a dynamic-size head copy cost more than the
/// rest of a step's markers.
Eigen::Vector3d column3(const Positions& q, int i) {
  return {q(0, i), q.rows() > 1 ? q(1, i) : 0.0, q.rows() > 2 ? q(2, i) : 0.0};
}

visualization_msgs::Marker base(const std::string& ns, int id, int type, const ros::Time& stamp) {
  visualization_msgs::Marker m;
  m.header.frame_id = "world";
  m.header.stamp = stamp;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = m.scale.y = m.scale.z = 1.0;
  return m;
}

geometry_msgs::Vector3 vector3(const Vector3& v) {
  geometry_msgs::Vector3 m;
  m.x = v.x();
  m.y = v.y();
  m.z = v.z();
  return m;
}

}  // namespace

double agentSphereRadius(const Formation& formation) {
  double scale = formation.edges().empty() ? 1.0 : HUGE_VAL;
  for (const Edge& e : formation.edges()) scale = std::min(scale, e.desiredDistance);
  return std::max(0.05, 0.1 * scale);
}

std_msgs::ColorRGBA agentColour(int agent) {
  static const double palette[8][3] = {{0.90, 0.10, 0.10}, {0.10, 0.45, 0.90}, {0.10, 0.75, 0.20},
                                       {0.95, 0.60, 0.05}, {0.60, 0.20, 0.80}, {0.05, 0.80, 0.80},
                                       {0.90, 0.30, 0.65}, {0.55, 0.40, 0.20}};
  const auto& c = palette[agent % 8];
  return rgba(c[0], c[1], c[2], 1.0);
}

FormationStatus toStatusMessage(const FormationSnapshot& s) {
  FormationStatus msg;
  msg.header.stamp = ros::Time::now();
  msg.header.frame_id = "world";
  msg.step = s.metrics.step;
  msg.time = s.metrics.time;
  msg.energy = s.metrics.energy;
  msg.agent_energy.assign(s.agentEnergy.data(), s.agentEnergy.data() + s.agentEnergy.size());
  msg.edge_distance_error.assign(s.edgeDistanceErrors.data(),
                                 s.edgeDistanceErrors.data() + s.edgeDistanceErrors.size());
  msg.max_distance_error = s.metrics.maxDistanceError;
  msg.linear_momentum = vector3(s.metrics.linearMomentum);
  msg.linear_momentum_predicted = vector3(s.linearMomentumPredicted);
  msg.angular_momentum = vector3(s.metrics.angularMomentum);
  msg.angular_momentum_predicted = vector3(s.angularMomentumPredicted);
  msg.converged = s.converged;
  msg.converged_step = s.convergedStep;
  return msg;
}

namespace {

using visualization_msgs::Marker;

/// Where the desired shape is drawn: its agents moved so that its centroid is the formation's,
/// and, under a commanded motion, turned and scaled as the commands have so far.
struct Ghost {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();         ///< of the current positions
  Eigen::Vector3d desiredCentroid = Eigen::Vector3d::Zero();  ///< of the desired shape
  CommandedFrame frame;

  Ghost(const FormationSnapshot& s, const Formation& formation, const CommandSchedule* schedule, double h) {
    const int n = formation.agentCount();
    for (int i = 0; i < n; ++i) {
      centroid += column3(s.positions, i) / n;
      desiredCentroid += column3(formation.desiredShape(), i) / n;
    }
    if (schedule) frame = commandedFrame(*schedule, s.metrics.step, h);
  }
  geometry_msgs::Point agent(const Formation& formation, int i) const {
    return point(frame.scale * (frame.rotation * (column3(formation.desiredShape(), i) - desiredCentroid)) + centroid);
  }
};

/// The commanded velocity v* as an arrow from the centroid (its length: one second of travel);
/// deleted while v* is zero.
Marker commandArrow(const Ghost& ghostAt, double radius, const ros::Time& stamp) {
  Marker m = base("command", 0, Marker::ARROW, stamp);
  if (ghostAt.frame.velocity.isZero(0.0)) {
    m.action = Marker::DELETE;
    return m;
  }
  m.points.push_back(point(ghostAt.centroid));
  m.points.push_back(point(ghostAt.centroid + ghostAt.frame.velocity));
  m.scale.x = 0.3 * radius;  // shaft diameter
  m.scale.y = 0.7 * radius;  // head diameter
  m.scale.z = 0.0;           // default head length
  m.color = rgba(1.0, 0.85, 0.1, 0.9);
  return m;
}

/// The agents as one sphere list (a sphere of its colour at each q_i): one marker whatever the
/// agent count, the same spheres rviz would draw from a marker per agent.
Marker agentSpheres(const FormationSnapshot& s, int n, double radius, AgentSpheres look, const ros::Time& stamp) {
  Marker agents = base("agents", 0, Marker::SPHERE_LIST, stamp);
  agents.scale.x = agents.scale.y = agents.scale.z = 2.0 * radius;
  agents.color = rgba(1.0, 1.0, 1.0, 1.0);  // rviz takes colors[] per point
  agents.points.reserve(static_cast<std::size_t>(n));
  agents.colors.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    agents.points.push_back(point(column3(s.positions, i)));
    agents.colors.push_back(agentColour(i));
    if (look == AgentSpheres::Halos) agents.colors.back().a = kHaloAlpha;
  }
  return agents;
}

/// The trails as one line list: per agent, segments through its kept positions (Trails) and on
/// to q_i, in its colour, faded.
Marker trailLines(const FormationSnapshot& s, const Trails& trails, double radius, const ros::Time& stamp) {
  const int n = trails.agents();
  Marker lines = base("trails", 0, Marker::LINE_LIST, stamp);
  lines.scale.x = 0.25 * radius;
  std::size_t segments = 0;
  for (int i = 0; i < n; ++i) segments += trails.of(i).size() + 1;  // at most
  lines.points.reserve(2 * segments);
  lines.colors.reserve(2 * segments);
  lines.color = rgba(1.0, 1.0, 1.0, 0.6);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d q = column3(s.positions, i);
    std_msgs::ColorRGBA faded = agentColour(i);
    faded.a = 0.6f;
    const std::deque<Eigen::Vector3d>& kept = trails.of(i);
    const Eigen::Vector3d* from = kept.empty() ? &q : &kept.front();
    const auto segment = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
      lines.points.push_back(point(a));
      lines.points.push_back(point(b));
      lines.colors.push_back(faded);
      lines.colors.push_back(faded);
    };
    for (std::size_t k = 1; k < kept.size(); ++k) {
      segment(*from, kept[k]);
      from = &kept[k];
    }
    // On to the current position (none if it is the last kept one; a dot at the start).
    if (*from != q || kept.size() < 2) segment(*from, q);
  }
  return lines;
}

/// The edges, green (no error) to red (|error| >= 10% of s d_ij, s the commanded scale), and, with
/// `ghostToo`, the desired shape's edges as a faint ghost; nothing without edges.
void addEdgesAndGhostEdges(const FormationSnapshot& s, const Formation& formation, const Ghost& ghostAt,
                           double radius, const ros::Time& stamp, bool ghostToo,
                           visualization_msgs::MarkerArray& out) {
  Marker edges = base("edges", 0, Marker::LINE_LIST, stamp);
  edges.scale.x = 0.3 * radius;
  edges.color = rgba(0.2, 0.8, 0.2, 1.0);
  Marker ghost = base("desired_shape", 0, Marker::LINE_LIST, stamp);
  ghost.scale.x = 0.2 * radius;
  ghost.color = rgba(0.7, 0.7, 0.7, 0.35);
  edges.points.reserve(2 * formation.edges().size());
  edges.colors.reserve(2 * formation.edges().size());
  if (ghostToo) ghost.points.reserve(2 * formation.edges().size());
  for (std::size_t e = 0; e < formation.edges().size(); ++e) {
    const Edge& edge = formation.edges()[e];
    // The status's error, against s d_ij under a commanded scale s.
    const double wanted = s.scale * edge.desiredDistance;
    const double error = s.edgeDistanceErrors(static_cast<Eigen::Index>(e));
    const double badness = std::min(1.0, std::abs(error) / (0.1 * std::max(wanted, 1e-9)));
    const std_msgs::ColorRGBA c = rgba(badness, 1.0 - 0.8 * badness, 0.1, 1.0);
    for (int end : {edge.tail, edge.head}) {
      edges.points.push_back(point(column3(s.positions, end)));
      edges.colors.push_back(c);
      if (ghostToo) ghost.points.push_back(ghostAt.agent(formation, end));
    }
  }
  if (!edges.points.empty()) {
    out.markers.push_back(std::move(edges));
    if (ghostToo) out.markers.push_back(std::move(ghost));
  }
}

/// The desired shape's agents as faint spheres.
Marker ghostAgents(const Formation& formation, const Ghost& ghostAt, double radius, const ros::Time& stamp) {
  Marker m = base("desired_shape", 1, Marker::SPHERE_LIST, stamp);
  m.scale.x = m.scale.y = m.scale.z = 1.2 * radius;
  m.color = rgba(0.7, 0.7, 0.7, 0.25);
  m.points.reserve(static_cast<std::size_t>(formation.agentCount()));
  for (int i = 0; i < formation.agentCount(); ++i) m.points.push_back(ghostAt.agent(formation, i));
  return m;
}

/// Step, time, energy, error and convergence, beside the formation (beyond its largest y and
/// z), not on top of its agents.
Marker statusText(const FormationSnapshot& s, int agents, const Ghost& ghostAt, double radius,
                  const ros::Time& stamp) {
  Marker text = base("text", 0, Marker::TEXT_VIEW_FACING, stamp);
  Eigen::Vector3d corner = column3(s.positions, 0);
  for (int i = 1; i < agents; ++i) corner = corner.cwiseMax(column3(s.positions, i));
  text.pose.position = point(Eigen::Vector3d(ghostAt.centroid.x(), corner.y() + 4.0 * radius,
                                             corner.z() + 2.0 * radius));
  text.scale.z = 1.5 * radius;
  text.color = rgba(1.0, 1.0, 1.0, 1.0);
  char buf[160];
  std::snprintf(buf, sizeof buf, "step %ld  t %.3f s\nE %.3e  error %.3e m%s", s.metrics.step,
                s.metrics.time, s.metrics.energy, s.metrics.maxDistanceError,
                s.converged ? "  converged" : "");
  text.text = buf;
  return text;
}

/// Whole steps of h that cover `period` seconds, at least 1 (a period that is a whole number of
/// steps up to round-off gives that number).
long stepsCovering(double period, double timeStep) {
  return std::max(1L, static_cast<long>(std::ceil(period / timeStep - 1e-9)));
}

}  // namespace

long markerEvery(long requested, double timeStep) {
  if (requested < 0) {
    throw InvalidInput("~marker_every: must be >= 0 (0: the markers of one step in every 0.02 s of simulated time), got " +
                       std::to_string(requested));
  }
  return requested > 0 ? requested : stepsCovering(kMarkerPeriod, timeStep);
}

long allMarkersEvery(int trailStride, double timeStep) {
  return std::max(static_cast<long>(trailStride), stepsCovering(kAllMarkersPeriod, timeStep));
}

visualization_msgs::MarkerArray makeMarkers(const FormationSnapshot& s, const Formation& formation,
                                            const Trails& trails, const CommandSchedule* schedule,
                                            double timeStep, MarkerParts parts, AgentSpheres spheres) {
  visualization_msgs::MarkerArray out;
  out.markers.reserve(6);
  const ros::Time stamp = ros::Time::now();
  const int n = formation.agentCount();
  const double radius = agentSphereRadius(formation);
  const Ghost ghostAt(s, formation, schedule, timeStep);
  const bool all = parts == MarkerParts::All;
  out.markers.push_back(agentSpheres(s, n, radius, spheres, stamp));
  if (all) out.markers.push_back(trailLines(s, trails, radius, stamp));
  addEdgesAndGhostEdges(s, formation, ghostAt, radius, stamp, all, out);
  if (all) out.markers.push_back(ghostAgents(formation, ghostAt, radius, stamp));
  out.markers.push_back(statusText(s, n, ghostAt, radius, stamp));
  if (schedule) out.markers.push_back(commandArrow(ghostAt, radius, stamp));
  return out;
}

void addSafetyMarkers(const FormationSnapshot& s, const SafetySettings& safety, const std::vector<Obstacle>& obstacles,
                      visualization_msgs::MarkerArray& out) {
  using visualization_msgs::Marker;
  const ros::Time stamp = ros::Time::now();
  const Positions& q = s.positions;
  const bool flat = q.rows() == 2;
  const double thickness = 0.02;  // [m] of a disc on the plane
  SpatialGrid grid;
  grid.build(q, safety.sensingRadius);
  std::vector<int> near;
  for (int i = 0; i < static_cast<int>(q.cols()); ++i) {
    near.clear();
    grid.within(q, i, safety.sensingRadius, near);
    double closest = safety.sensingRadius;
    for (int j : near) closest = std::min(closest, (q.col(i) - q.col(j)).norm());
    // 0 at r or nearer, 1 at R or farther: red, through yellow, to green.
    const double t = std::clamp((closest - safety.radius) / (safety.sensingRadius - safety.radius), 0.0, 1.0);
    Marker disc = base("safety_discs", i, flat ? Marker::CYLINDER : Marker::SPHERE, stamp);
    disc.pose.position = point(column3(q, i));
    disc.scale.x = disc.scale.y = safety.radius;  // diameter r: radius r/2
    disc.scale.z = flat ? thickness : safety.radius;
    disc.color = rgba(std::min(1.0, 2.0 - 2.0 * t), std::min(1.0, 2.0 * t), 0.1, 0.45);
    out.markers.push_back(disc);
  }
  for (std::size_t k = 0; k < obstacles.size(); ++k) {
    const Obstacle& o = obstacles[k];
    const bool ball = o.shape == Obstacle::Shape::Ball;
    Marker m = base("obstacles", static_cast<int>(k), ball ? (flat ? Marker::CYLINDER : Marker::SPHERE) : Marker::CUBE,
                    stamp);
    const Eigen::Vector3d centre = ball ? o.centre : Eigen::Vector3d(0.5 * (o.min + o.max));
    const Eigen::Vector3d size = ball ? Eigen::Vector3d::Constant(2.0 * o.radius) : Eigen::Vector3d(o.max - o.min);
    m.pose.position = point(centre);
    m.scale.x = std::max(size.x(), 1e-3);
    m.scale.y = std::max(size.y(), 1e-3);
    m.scale.z = flat ? 0.3 : std::max(size.z(), 1e-3);  // a low wall on the plane
    if (flat) m.pose.position.z = 0.15;
    m.color = rgba(0.45, 0.45, 0.45, 0.8);
    out.markers.push_back(m);
  }
}

}  // namespace vf
