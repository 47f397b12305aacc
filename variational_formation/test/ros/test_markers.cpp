// The monitor's rviz markers (src/ros/markers.cpp) and the trails they draw (src/ros/trails.cpp):
// a fixed handful of markers whatever the agent count, each holding the right points.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <ros/serialization.h>
#include <ros/time.h>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation/ros/frames.hpp"
#include "variational_formation/ros/markers.hpp"

namespace vf {
namespace {

using visualization_msgs::Marker;

/// A ring of n agents 1 m apart with chords to the second neighbour (2n edges).
Formation ring(int n) {
  const double radius = 0.5 / std::sin(M_PI / n);
  Positions shape(2, n);
  for (int i = 0; i < n; ++i) shape.col(i) << radius * std::cos(2 * M_PI * i / n), radius * std::sin(2 * M_PI * i / n);
  std::vector<std::pair<int, int>> edges;
  for (int i = 0; i < n; ++i) {
    edges.emplace_back(i, (i + 1) % n);
    edges.emplace_back(i, (i + 2) % n);
  }
  return Formation(2, shape, edges);
}

/// Agent i's position at step k: the desired shape drifting by (0.01 k, 0.002 k i) m.
Positions positionsAt(const Formation& f, long k) {
  Positions q = f.desiredShape();
  for (int i = 0; i < f.agentCount(); ++i) q.col(i) += Eigen::Vector2d(0.01 * k, 0.002 * k * i);
  return q;
}

/// Step k's snapshot, its edge errors measured as the monitor measures them (|q_i - q_j| - d_ij).
FormationSnapshot snapshotAt(const Formation& f, long k) {
  FormationSnapshot s;
  s.metrics.step = k;
  s.positions = positionsAt(f, k);
  s.edgeDistanceErrors.resize(static_cast<Eigen::Index>(f.edges().size()));
  for (std::size_t e = 0; e < f.edges().size(); ++e) {
    const Edge& edge = f.edges()[e];
    s.edgeDistanceErrors(static_cast<Eigen::Index>(e)) =
        (s.positions.col(edge.tail) - s.positions.col(edge.head)).norm() - edge.desiredDistance;
  }
  return s;
}

/// The markers of step `last` after `trails` saw steps 0..last.
visualization_msgs::MarkerArray markersAfter(const Formation& f, long last, Trails& trails) {
  for (long k = 0; k <= last; ++k) trails.add(k, positionsAt(f, k));
  return makeMarkers(snapshotAt(f, last), f, trails);
}

const Marker& find(const visualization_msgs::MarkerArray& a, const std::string& ns, int id) {
  for (const Marker& m : a.markers) {
    if (m.ns == ns && m.id == id) return m;
  }
  static const Marker none;
  ADD_FAILURE() << "no marker " << ns << " " << id;
  return none;
}

void expectPoint(const geometry_msgs::Point& p, const Eigen::Vector2d& q, const std::string& what) {
  EXPECT_EQ(p.x, q.x()) << what;
  EXPECT_EQ(p.y, q.y()) << what;
  EXPECT_EQ(p.z, 0.0) << what;
}

void expectColour(const std_msgs::ColorRGBA& c, const std_msgs::ColorRGBA& want, float alpha, const std::string& what) {
  EXPECT_EQ(c.r, want.r) << what;
  EXPECT_EQ(c.g, want.g) << what;
  EXPECT_EQ(c.b, want.b) << what;
  EXPECT_EQ(c.a, alpha) << what;
}

class MarkersTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { ros::Time::init(); }
};

TEST_F(MarkersTest, AgentsAreOneSphereListOfTheirPositionsAndColours) {
  for (int n : {6, 300}) {
    const Formation f = ring(n);
    Trails trails(n, 100);
    const auto a = markersAfter(f, 40, trails);
    const Marker& agents = find(a, "agents", 0);
    EXPECT_EQ(agents.type, Marker::SPHERE_LIST);
    ASSERT_EQ(agents.points.size(), static_cast<std::size_t>(n));
    ASSERT_EQ(agents.colors.size(), static_cast<std::size_t>(n));
    const Positions q = positionsAt(f, 40);
    for (int i = 0; i < n; ++i) {
      expectPoint(agents.points[i], q.col(i), "agent " + std::to_string(i));
      expectColour(agents.colors[i], agentColour(i), 1.0f, "agent " + std::to_string(i));
    }
    // A tenth of the shortest desired edge (1 m, to rounding) as radius: spheres 0.2 m across.
    EXPECT_NEAR(agents.scale.x, 0.2, 1e-12);
  }
}

// A robot run (the monitor's ~measure_robots): the same spheres as translucent halos, so that the
// robots' bodies inside them (the world's solid markers) show; nothing else changes.
TEST_F(MarkersTest, RobotRunsDrawTheAgentsAsHalos) {
  const Formation f = ring(6);
  Trails trails(6, 100);
  for (long k = 0; k <= 40; ++k) trails.add(k, positionsAt(f, k));
  const auto solid = makeMarkers(snapshotAt(f, 40), f, trails);
  const auto halos = makeMarkers(snapshotAt(f, 40), f, trails, nullptr, 0.0, MarkerParts::All, AgentSpheres::Halos);
  const Marker& agents = find(halos, "agents", 0);
  ASSERT_EQ(agents.colors.size(), 6u);
  for (int i = 0; i < 6; ++i) expectColour(agents.colors[i], agentColour(i), kHaloAlpha, "agent " + std::to_string(i));
  EXPECT_LE(kHaloAlpha, 0.5f);
  EXPECT_EQ(agents.points, find(solid, "agents", 0).points);
  EXPECT_EQ(agents.scale.x, find(solid, "agents", 0).scale.x);
  ASSERT_EQ(halos.markers.size(), solid.markers.size());
  for (std::size_t k = 0; k < solid.markers.size(); ++k) {
    if (solid.markers[k].ns != "agents") {
      EXPECT_EQ(halos.markers[k].colors, solid.markers[k].colors) << solid.markers[k].ns;
    }
  }
}

TEST_F(MarkersTest, EdgesAreOneLineListTailThenHeadColouredByTheirError) {
  const int n = 300;
  const Formation f = ring(n);
  Trails trails(n, 100);
  const auto a = markersAfter(f, 40, trails);
  const Marker& edges = find(a, "edges", 0);
  EXPECT_EQ(edges.type, Marker::LINE_LIST);
  ASSERT_EQ(edges.points.size(), 2 * f.edges().size());
  ASSERT_EQ(edges.colors.size(), 2 * f.edges().size());
  const FormationSnapshot s = snapshotAt(f, 40);
  for (std::size_t e = 0; e < f.edges().size(); ++e) {
    const Edge& edge = f.edges()[e];
    expectPoint(edges.points[2 * e], s.positions.col(edge.tail), "tail of edge " + std::to_string(e));
    expectPoint(edges.points[2 * e + 1], s.positions.col(edge.head), "head of edge " + std::to_string(e));
    // Red share: |error| / (10% of d_ij), at most 1.
    const double red = std::min(1.0, std::abs(s.edgeDistanceErrors(static_cast<Eigen::Index>(e))) / (0.1 * edge.desiredDistance));
    EXPECT_NEAR(edges.colors[2 * e].r, red, 1e-6) << e;
    EXPECT_EQ(edges.colors[2 * e].r, edges.colors[2 * e + 1].r) << e;
  }
  // The drift stretches the ring's far edges by more than 10%, the near ones by less.
  EXPECT_GT(edges.colors[0].r, 0.0f);
  EXPECT_LT(edges.colors[0].r, 1.0f);
  EXPECT_EQ(edges.colors.back().r, 1.0f);
}

TEST_F(MarkersTest, SmallFormationsKeepEveryStepOfTheirTrails) {
  const int n = 6, length = 100;
  const Formation f = ring(n);
  Trails trails(n, length);
  EXPECT_EQ(trails.stride(), 1);
  const long last = 150;
  const auto a = markersAfter(f, last, trails);
  const Marker& lines = find(a, "trails", 0);
  EXPECT_EQ(lines.type, Marker::LINE_LIST);
  // Per agent, the segments between the positions of steps 51..150: 99 segments.
  ASSERT_EQ(lines.points.size(), static_cast<std::size_t>(n * 2 * (length - 1)));
  ASSERT_EQ(lines.colors.size(), lines.points.size());
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < length - 1; ++k) {
      const std::size_t v = static_cast<std::size_t>(2 * ((length - 1) * i + k));
      const long step = last - length + 1 + k;
      expectPoint(lines.points[v], positionsAt(f, step).col(i), "trail " + std::to_string(i));
      expectPoint(lines.points[v + 1], positionsAt(f, step + 1).col(i), "trail " + std::to_string(i));
      expectColour(lines.colors[v], agentColour(i), 0.6f, "trail " + std::to_string(i));
    }
  }
}

TEST_F(MarkersTest, TrailsHoldAtMost600PositionsOrTwoPerAgent) {
  // 100 agents: a position every ceil(100 x 100 / 600) = 17 steps, 5 per trail (steps 17 k).
  const Formation f = ring(100);
  Trails trails(100, 100);
  EXPECT_EQ(trails.stride(), 17);
  const auto a = markersAfter(f, 400, trails);
  ASSERT_EQ(trails.of(7).size(), 5u);
  EXPECT_EQ(trails.of(7).front().head<2>(), Eigen::Vector2d(positionsAt(f, 323).col(7)));
  EXPECT_EQ(trails.of(7).back().head<2>(), Eigen::Vector2d(positionsAt(f, 391).col(7)));
  // Per agent, 4 segments between kept positions and one on to step 400.
  EXPECT_EQ(find(a, "trails", 0).points.size(), 100u * 2 * 5);
  // Trails of 2 steps never thin: every step kept.
  EXPECT_EQ(Trails(1000, 2).stride(), 1);
}

TEST_F(MarkersTest, LargeFormationsThinTheirTrailsToABoundOverTheSameSpan) {
  const int n = 1000, length = 100;
  const Formation f = ring(n);
  Trails trails(n, length);
  // ceil(1000 x 100 / 600) = 167, at most 100 / 2: positions of every 50th step, two per trail.
  ASSERT_EQ(trails.stride(), 50);
  const long last = 337;
  const auto a = markersAfter(f, last, trails);
  for (int i = 0; i < n; ++i) ASSERT_EQ(trails.of(i).size(), 2u);
  const Marker& lines = find(a, "trails", 0);
  // Per agent: steps 250 -> 300, then 300 -> 337 (the current position).
  ASSERT_EQ(lines.points.size(), static_cast<std::size_t>(4 * n));
  for (int i = 0; i < n; ++i) {
    const std::string what = "trail " + std::to_string(i);
    expectPoint(lines.points[4 * i], positionsAt(f, 250).col(i), what);
    expectPoint(lines.points[4 * i + 1], positionsAt(f, 300).col(i), what);
    expectPoint(lines.points[4 * i + 2], positionsAt(f, 300).col(i), what);
    expectPoint(lines.points[4 * i + 3], positionsAt(f, last).col(i), what);
  }
  // At step 0 a trail is a dot at the agent.
  Trails fresh(n, length);
  const Marker& dots = find(markersAfter(f, 0, fresh), "trails", 0);
  ASSERT_EQ(dots.points.size(), static_cast<std::size_t>(2 * n));
  expectPoint(dots.points[0], positionsAt(f, 0).col(0), "dot");
  expectPoint(dots.points[1], positionsAt(f, 0).col(0), "dot");
}

TEST_F(MarkersTest, TheArrayHasAFixedHandfulOfMarkersAndGrowsLinearlyWithTheAgents) {
  // The same markers for 6 and 1000 agents (no commands: no arrow); the message at 1000 agents,
  // with a ring's 2000 edges, under 500 kB (it was 3 MB with a sphere and a strip per agent).
  std::vector<std::pair<std::string, int>> names6, names1000;
  uint32_t bytes = 0;
  for (int n : {6, 1000}) {
    const Formation f = ring(n);
    Trails trails(n, 100);
    const auto a = markersAfter(f, 120, trails);
    auto& names = n == 6 ? names6 : names1000;
    for (const Marker& m : a.markers) names.emplace_back(m.ns, m.id);
    bytes = ros::serialization::serializationLength(a);
  }
  EXPECT_EQ(names6, names1000);
  EXPECT_EQ(names6.size(), 6u);  // agents, trails, edges, desired_shape 0 and 1, text
  EXPECT_LT(bytes, 500000u);
}

TEST_F(MarkersTest, MovingPartsLeaveOutTheTrailsAndTheGhostOnly) {
  const int n = 100;
  const Formation f = ring(n);
  Trails trails(n, 100);
  const auto all = markersAfter(f, 40, trails);
  const auto moving = makeMarkers(snapshotAt(f, 40), f, trails, nullptr, 0.005, MarkerParts::Moving);
  std::vector<std::pair<std::string, int>> names;
  for (const Marker& m : moving.markers) names.emplace_back(m.ns, m.id);
  const std::vector<std::pair<std::string, int>> want{{"agents", 0}, {"edges", 0}, {"text", 0}};
  EXPECT_EQ(names, want);
  // What it holds is what the whole array holds, point for point.
  for (const auto& [ns, id] : want) {
    const Marker& a = find(all, ns, id);
    const Marker& b = find(moving, ns, id);
    EXPECT_EQ(a.points, b.points) << ns;
    EXPECT_EQ(a.colors, b.colors) << ns;
    EXPECT_EQ(a.text, b.text) << ns;
  }
  // Under half the bytes: the trails and the ghost are most of a 100-agent ring's array.
  EXPECT_LT(2 * ros::serialization::serializationLength(moving), ros::serialization::serializationLength(all));
}

TEST_F(MarkersTest, WholeArraysComeAsOftenAsTheTrailsGrowAndAtMost25ASimulatedSecond) {
  EXPECT_EQ(allMarkersEvery(1, 0.005), 8);   // 0.04 s / 0.005 s
  EXPECT_EQ(allMarkersEvery(1, 0.014), 3);   // ceil(2.86)
  EXPECT_EQ(allMarkersEvery(1, 0.04), 1);    // exactly one step
  EXPECT_EQ(allMarkersEvery(1, 0.1), 1);
  EXPECT_EQ(allMarkersEvery(17, 0.005), 17);  // 100 agents: the trails' stride
  EXPECT_EQ(allMarkersEvery(50, 0.001), 50);
  EXPECT_EQ(allMarkersEvery(1, 0.0001), 400);
}

TEST_F(MarkersTest, MarkersComeEveryRequestedStepOrFiftyASimulatedSecond) {
  // 0 (the default): one step in every 0.02 s of simulated time, at least every step.
  EXPECT_EQ(markerEvery(0, 0.005), 4);     // 0.02 s / 0.005 s
  EXPECT_EQ(markerEvery(0, 0.014), 2);     // ceil(1.43): hexagon.yaml
  EXPECT_EQ(markerEvery(0, 0.02), 1);      // exactly one step
  EXPECT_EQ(markerEvery(0, 0.1), 1);       // steps longer than the period: every step
  EXPECT_EQ(markerEvery(0, 0.0001628), 123);  // ceil(122.85)
  // A requested k is kept, whatever h.
  EXPECT_EQ(markerEvery(1, 0.005), 1);
  EXPECT_EQ(markerEvery(10, 0.1), 10);
  try {
    markerEvery(-1, 0.005);
    FAIL() << "a negative ~marker_every was taken";
  } catch (const InvalidInput& e) {
    EXPECT_EQ(std::string(e.what()),
              "~marker_every: must be >= 0 (0: the markers of one step in every 0.02 s of simulated time), got -1");
  }
}

TEST(Frames, AReusedTransformIsWrittenWhole) {
  std_msgs::Header header;
  header.stamp = ros::Time(1.25);
  header.frame_id = "world";
  const geometry_msgs::TransformStamped fresh = frameAt(header, "formation/agent_12", {1.5, -2.0});
  // A transform left over from another frame, rotated, 3-D, with a longer name.
  geometry_msgs::TransformStamped reused = frameAt(header, "a_much_longer_frame_name_than_before", {7.0, 8.0, 9.0});
  reused.header.seq = 41;
  reused.transform.rotation.x = reused.transform.rotation.y = reused.transform.rotation.z = 0.5;
  setFrameAt(reused, header, "formation/agent_12", {1.5, -2.0});
  EXPECT_EQ(reused, fresh);
  EXPECT_EQ(reused.transform.translation.z, 0.0);  // planar: z = 0
  EXPECT_EQ(reused.transform.rotation.w, 1.0);
}

}  // namespace
}  // namespace vf
