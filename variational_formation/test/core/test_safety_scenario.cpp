// The scenario's `safety:` block and `obstacles:` list through the one loader: what loads, and
// each refusal in one line naming the field, the value and why.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "test_support.hpp"
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/model/validation.hpp"

namespace vf {
namespace {

// Three agents 1 m apart (desired) starting 0.6 m apart; a disc and a box well clear of them.
const std::string kBase =
    "name: t\ndimension: 2\nkappa: 2\ntime_step: 0.02\nsteps: 10\n"
    "agents:\n"
    "  - {id: 0, initial_position: [0, 0], desired_position: [0, 0]}\n"
    "  - {id: 1, initial_position: [0.6, 0], desired_position: [1, 0]}\n"
    "  - {id: 2, initial_position: [0, 0.6], desired_position: [0.5, 0.8660254037844386]}\n"
    "edges: [[0, 1], [1, 2], [2, 0]]\n";
const std::string kSafety = "safety: {radius: 0.25, sensing_radius: 1.0, gamma: 0.2}\n";
const std::string kObstacles =
    "obstacles:\n"
    "  - {center: [3, 0], radius: 0.5}\n"
    "  - {min: [-2, -2], max: [-1, 2]}\n";

using test::replaced;
using test::expectError;

TEST(SafetyScenario, WithoutTheBlockNothingChanges) {
  const Scenario s = parseScenario(kBase, "file.yaml");
  EXPECT_FALSE(s.safety.has_value());
  EXPECT_TRUE(s.obstacles.empty());
}

TEST(SafetyScenario, LoadsTheBlockAndTheObstacles) {
  const Scenario s = parseScenario(kBase + kSafety + kObstacles, "file.yaml");
  ASSERT_TRUE(s.safety.has_value());
  EXPECT_EQ(s.safety->radius, 0.25);
  EXPECT_EQ(s.safety->sensingRadius, 1.0);
  EXPECT_EQ(s.safety->gamma, 0.2);
  EXPECT_EQ(s.safety->maxSpeed, std::numeric_limits<double>::infinity());
  EXPECT_EQ(s.safety->blockedAfter, 10.0);
  ASSERT_EQ(s.obstacles.size(), 2u);
  EXPECT_EQ(s.obstacles[0].shape, Obstacle::Shape::Ball);
  EXPECT_EQ(s.obstacles[0].centre, Eigen::Vector3d(3, 0, 0));
  EXPECT_EQ(s.obstacles[0].radius, 0.5);
  EXPECT_EQ(s.obstacles[1].shape, Obstacle::Shape::Box);
  EXPECT_EQ(s.obstacles[1].min, Eigen::Vector3d(-2, -2, 0));
  EXPECT_EQ(s.obstacles[1].max, Eigen::Vector3d(-1, 2, 0));
  const Scenario t = parseScenario(
      kBase + "safety: {radius: 0.25, sensing_radius: 1.0, gamma: 1, max_speed: 0.5, blocked_after: 4}\n",
      "file.yaml");
  EXPECT_EQ(t.safety->maxSpeed, 0.5);
  EXPECT_EQ(t.safety->blockedAfter, 4.0);
  EXPECT_EQ(t.safety->gamma, 1.0);
  EXPECT_TRUE(t.warnings.empty());
  // The boundaries are accepted: a start exactly r apart, r/2 from an obstacle.
  parseScenario(replaced(kBase, "[0.6, 0], desired", "[0.25, 0], desired") + kSafety +
                    "obstacles: [{min: [-1, -1], max: [1, -0.125]}]\n",
                "file.yaml");
}

TEST(SafetyScenario, RefusesBadNumbers) {
  expectError(kBase + "safety: {radius: 0.25, gamma: 0.2}\n", {"safety.sensing_radius: missing"});
  expectError(kBase + "safety: {radius: 0, sensing_radius: 1, gamma: 0.2}\n", {"safety.radius", "> 0", "got 0"});
  expectError(kBase + "safety: {radius: 0.25, sensing_radius: 0.25, gamma: 0.2}\n",
                {"safety.sensing_radius: must be > safety.radius = 0.25 m", "got 0.25"});
  expectError(kBase + "safety: {radius: 0.25, sensing_radius: 1, gamma: 0}\n", {"safety.gamma", "(0, 1]", "got 0"});
  expectError(kBase + "safety: {radius: 0.25, sensing_radius: 1, gamma: 1.5}\n", {"safety.gamma", "got 1.5"});
  expectError(kBase + "safety: {radius: 0.25, sensing_radius: 1, gamma: -0.1}\n", {"safety.gamma", "got -0.1"});
  expectError(kBase + "safety: {radius: 0.25, sensing_radius: 1, gamma: 0.2, max_speed: 0}\n",
                {"safety.max_speed", "got 0"});
  expectError(kBase + "safety: {radius: 0.25, sensing_radius: 1, gamma: 0.2, blocked_after: -1}\n",
                {"safety.blocked_after", "got -1"});
  expectError(kBase + "safety: {radius: 0.25, sensing_radius: 1, gamma: 0.2, speed: 1}\n",
                {"safety.speed: unknown field"});
  expectError(kBase + "safety: [0.25]\n", {"safety: expected a mapping"});
}

TEST(SafetyScenario, RefusesBadObstacles) {
  expectError(kBase + kObstacles, {"obstacles: need a safety: block"});
  expectError(kBase + kSafety + "obstacles: [{center: [1, 2, 3], radius: 1}]\n",
                {"obstacles[0].center: expected 2 coordinates (dimension 2), got 3"});
  expectError(kBase + kSafety + "obstacles: [{center: [3, 3], radius: -1}]\n",
                {"obstacles[0].radius", ">= 0", "got -1"});
  expectError(kBase + kSafety + "obstacles: [{min: [3, 3], max: [4, 2]}]\n",
                {"obstacles[0].min: coordinate 1 is 3, above max's 2"});
  expectError(kBase + kSafety + "obstacles: [{min: [3, 3]}]\n", {"obstacles[0].max: missing"});
  expectError(kBase + kSafety + "obstacles: [{center: [3, 3], radius: 1, max: [4, 4]}]\n",
                {"obstacles[0]: either {center, radius}", "not both"});
  expectError(kBase + kSafety + "obstacles: [{centre: [3, 3], radius: 1}]\n", {"obstacles[0].centre: unknown field"});
}

TEST(SafetyScenario, RefusesShapesAndStartsThatAreAlreadyTooClose) {
  expectError(replaced(kBase, "desired_position: [1, 0]", "desired_position: [0.2, 0]") + kSafety,
                {"agents[1].desired_position: 0.2 m from agent 0's", "closer than safety.radius = 0.25 m"});
  // A manoeuvre that shrinks the shape to half: 0.5 m apart at scale 0.4 is 0.2 m.
  expectError(replaced(kBase, "desired_position: [1, 0]", "desired_position: [0.5, 0]") + kSafety +
                    "manoeuvre: [{until: 1, scale: 1}, {scale: 0.4}]\n",
                {"agents[1].desired_position", "0.2 m at the manoeuvre's scale 0.4", "closer than safety.radius"});
  expectError(replaced(kBase, "[0.6, 0], desired", "[0.1, 0], desired") + kSafety,
                {"agents[1].initial_position: 0.1 m from agent 0's, closer than safety.radius = 0.25 m at the start"});
  expectError(kBase + kSafety + "obstacles: [{center: [0, -0.6], radius: 0.5}]\n",
                {"agents[0].initial_position", "from obstacles[0], closer than safety.radius / 2 = 0.125 m"});
  expectError(kBase + kSafety + "obstacles: [{min: [-1, -1], max: [0.1, 0.1]}]\n",
                {"agents[0].initial_position: 0 m from obstacles[0]"});
}

TEST(SafetyScenario, WarnsWhenMaxSpeedCanCrossTheSensingGapInOneStep) {
  const Scenario s =
      parseScenario(kBase + "safety: {radius: 0.25, sensing_radius: 1.0, gamma: 0.2, max_speed: 20}\n", "file.yaml");
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("safety.max_speed: two agents at 20 m/s close 0.8 m per step"), std::string::npos)
      << s.warnings[0];
}

}  // namespace
}  // namespace vf
