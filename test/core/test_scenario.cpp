// Scenario loading: one test per validation rule; every error names its field.
#include <gtest/gtest.h>

#include <string>

#include "test_support.hpp"
#include "variational_formation/core/error.hpp"

namespace vf {
namespace {

const std::string kHeader =
    "name: t\ndimension: 2\nkappa: 1.0\ntime_step: 0.01\nsteps: 10\n";
const std::string kAgents =
    "agents:\n"
    "  - {id: 0, initial_position: [0, 0], desired_position: [0, 0]}\n"
    "  - {id: 1, initial_position: [1, 0], initial_velocity: [0, 1], desired_position: [1, 0]}\n"
    "  - {id: 2, initial_position: [0, 1], desired_position: [0, 1]}\n";
const std::string kEdges = "edges: [[0, 1], [1, 2], [2, 0]]\n";

std::string valid() { return kHeader + kAgents + kEdges; }

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

// Expects InvalidInput whose message contains every fragment.
void expectError(const std::string& yaml, std::initializer_list<std::string> fragments) {
  try {
    parseScenario(yaml, "file.yaml");
    ADD_FAILURE() << "accepted:\n" << yaml;
  } catch (const InvalidInput& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_EQ(what.rfind("file.yaml: ", 0), 0u) << what;
    for (const auto& f : fragments) EXPECT_NE(what.find(f), std::string::npos) << what << " / " << f;
  }
}

TEST(Scenario, ValidFileLoads) {
  const Scenario s = parseScenario(valid(), "file.yaml");
  EXPECT_EQ(s.agentCount(), 3);
  EXPECT_EQ(s.initialVelocities(1, 1), 1.0);
  EXPECT_EQ(s.initialVelocities(0, 0), 0.0);  // omitted: at rest
  EXPECT_TRUE(s.warnings.empty());
}

TEST(Scenario, EveryShippedScenarioLoads) {
  for (const char* name : {"tetrahedron_paper", "tetrahedron", "square", "hexagon", "free_particle", "grid24"}) {
    const Scenario s = loadScenario(test::configPath(name));
    EXPECT_EQ(s.name, name);
    EXPECT_TRUE(s.warnings.empty()) << name << ": " << (s.warnings.empty() ? "" : s.warnings[0]);
  }
  EXPECT_GE(loadScenario(test::configPath("grid24")).agentCount(), 20);
}

TEST(Scenario, YamlSyntaxError) { expectError(kHeader + "agents: [\n", {"YAML error at line"}); }
TEST(Scenario, MissingFile) {
  EXPECT_THROW(loadScenario("/nonexistent/x.yaml"), InvalidInput);
}
TEST(Scenario, DirectoryIsNotAScenarioFile) {
  try {
    loadScenario(VF_SOURCE_DIR "/config");
    ADD_FAILURE() << "a directory was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
}
TEST(Scenario, TopLevelMustBeAMapping) { expectError("- 1\n- 2\n", {"top level"}); }
TEST(Scenario, MissingRequiredFields) {
  for (const std::string field : {"name", "dimension", "kappa", "time_step", "steps"}) {
    const auto start = valid().find(field + ":");
    std::string yaml = valid();
    yaml.erase(start, yaml.find('\n', start) - start + 1);
    expectError(yaml, {field + ": missing"});
  }
  expectError(kHeader + kEdges, {"agents: missing"});
  expectError(replaced(valid(), "initial_position: [0, 0], ", ""), {"agents[0].initial_position: missing"});
  expectError(replaced(valid(), ", desired_position: [0, 1]", ""), {"agents[2].desired_position: missing"});
  expectError(replaced(valid(), "id: 1, ", ""), {"agents[1].id: missing"});
}
TEST(Scenario, WrongTypes) {
  expectError(replaced(valid(), "kappa: 1.0", "kappa: fast"), {"kappa", "expected a number", "'fast'"});
  expectError(replaced(valid(), "steps: 10", "steps: 2.5"), {"steps", "expected an integer"});
  expectError(replaced(valid(), "dimension: 2", "dimension: [2]"), {"dimension", "expected an integer"});
  expectError(replaced(valid(), "name: t", "name: {a: 1}"), {"name", "non-empty string"});
  expectError(replaced(valid(), "initial_position: [1, 0]", "initial_position: 3"),
              {"agents[1].initial_position", "list of numbers"});
  expectError(replaced(valid(), "[2, 0]]", "[2, x]]"), {"edges[2][1]", "expected an integer"});
  expectError(replaced(valid(), "edges: [[0, 1], [1, 2], [2, 0]]", "edges: 3"), {"edges", "list"});
  expectError(replaced(valid(), "[1, 2],", "[1, 2, 0],"), {"edges[1]", "pair"});
  expectError(kHeader + "agents: [3]\n", {"agents[0]", "mapping"});
}
TEST(Scenario, DimensionMustBeTwoOrThree) {
  expectError(replaced(valid(), "dimension: 2", "dimension: 4"), {"dimension: must be 2 or 3"});
}
TEST(Scenario, CoordinateCountMatchesDimension) {
  expectError(replaced(valid(), "desired_position: [1, 0]", "desired_position: [1, 0, 0]"),
              {"agents[1].desired_position", "expected 2 coordinates"});
  expectError(replaced(valid(), "initial_velocity: [0, 1]", "initial_velocity: [0]"),
              {"agents[1].initial_velocity", "expected 2 coordinates"});
}
TEST(Scenario, IdsInOrderFromZero) {
  expectError(replaced(valid(), "id: 1", "id: 2"), {"agents[1].id", "expected 1, got 2"});
  expectError(replaced(valid(), "id: 0", "id: -1"), {"agents[0].id"});
}
TEST(Scenario, EdgeToMissingAgent) {
  expectError(replaced(valid(), "[2, 0]", "[2, 7]"), {"edges[2]", "agent 7 does not exist"});
  expectError(replaced(valid(), "[2, 0]", "[-1, 0]"), {"edges[2]", "agent -1 does not exist"});
}
TEST(Scenario, SelfEdge) { expectError(replaced(valid(), "[2, 0]", "[2, 2]"), {"edges[2]", "distinct"}); }
TEST(Scenario, DuplicateEdge) {
  expectError(replaced(valid(), "[2, 0]", "[0, 1]"), {"edges[2]", "duplicate"});
  expectError(replaced(valid(), "[2, 0]", "[1, 0]"), {"edges[2]", "duplicate"});
}
TEST(Scenario, NonFiniteNumbers) {
  expectError(replaced(valid(), "kappa: 1.0", "kappa: .nan"), {"kappa", "finite"});
  expectError(replaced(valid(), "time_step: 0.01", "time_step: .inf"), {"time_step", "finite"});
  expectError(replaced(valid(), "initial_position: [1, 0]", "initial_position: [1, .inf]"),
              {"agents[1].initial_position[1]", "finite"});
}
TEST(Scenario, TimeStepMustBePositive) {
  expectError(replaced(valid(), "time_step: 0.01", "time_step: 0"), {"time_step", "> 0"});
  expectError(replaced(valid(), "time_step: 0.01", "time_step: -0.1"), {"time_step", "> 0"});
}
TEST(Scenario, StepsNonNegative) {
  expectError(replaced(valid(), "steps: 10", "steps: -1"), {"steps", ">= 0"});
  Scenario s = parseScenario(replaced(valid(), "steps: 10", "steps: 0"), "file.yaml");
  EXPECT_EQ(s.steps, 0);  // unbounded: accepted for the ROS run
  EXPECT_THROW(validateScenario(s, /*requireBoundedSteps=*/true), InvalidInput);
}
TEST(Scenario, KappaNonNegative) {
  expectError(replaced(valid(), "kappa: 1.0", "kappa: -2"), {"kappa", ">= 0"});
}
TEST(Scenario, UnknownFieldsAreRejected) {
  expectError(replaced(valid(), "steps: 10", "stpes: 10"), {"stpes: unknown field"});
  expectError(replaced(valid(), "id: 2,", "id: 2, colour: red,"), {"agents[2].colour: unknown field"});
}
TEST(Scenario, EmptyAgents) { expectError(kHeader + "agents: []\n", {"agents", "non-empty"}); }
TEST(Scenario, NonRigidGraphIsAcceptedWithAWarning) {
  const Scenario s = parseScenario(replaced(valid(), ", [2, 0]]", "]"), "file.yaml");
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("not infinitesimally rigid"), std::string::npos);
}
TEST(Scenario, LargeTimeStepIsAcceptedWithAWarning) {
  const Scenario s = parseScenario(
      replaced(replaced(valid(), "time_step: 0.01", "time_step: 2.0"), "kappa: 1.0", "kappa: 0"), "file.yaml");
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("stability limit"), std::string::npos);
}

}  // namespace
}  // namespace vf
