// Scenario loading and the one validation path: one test per rule; every error names its field,
// the value and the limit; the boundary values are accepted.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>

#include "test_support.hpp"
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/model/validation.hpp"
#include "variational_formation_core/integrators/variational_update.hpp"

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

using test::expectError;
using test::replaced;

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
  expectError(replaced(valid(), "steps: 10", "steps: -1"), {"steps: must be between 0 and", "got -1"});
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
TEST(Scenario, RequireConvergenceIsABoolean) {
  EXPECT_FALSE(parseScenario(valid(), "file.yaml").requireConvergence);
  EXPECT_TRUE(parseScenario(replaced(valid(), "steps: 10", "steps: 10\nrequire_convergence: true"), "f").requireConvergence);
  EXPECT_FALSE(parseScenario(replaced(valid(), "steps: 10", "steps: 10\nrequire_convergence: false"), "f").requireConvergence);
  expectError(replaced(valid(), "steps: 10", "steps: 10\nrequire_convergence: 1"), {"require_convergence: expected true or false"});
  expectError(replaced(valid(), "steps: 10", "steps: 10\nrequire_convergence: [true]"), {"require_convergence: expected true or false"});
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


// --- The limits of README "Limits": each rejected value and the boundary still accepted. ---

double up(double x) { return std::nextafter(x, HUGE_VAL); }
double down(double x) { return std::nextafter(x, 0.0); }

// Expects `check` to throw InvalidInput, one line, containing every fragment.
void expectRejected(const std::function<void()>& check, std::initializer_list<std::string> fragments) {
  try {
    check();
    ADD_FAILURE() << "accepted: " << *fragments.begin();
  } catch (const InvalidInput& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    for (const auto& f : fragments) EXPECT_NE(what.find(f), std::string::npos) << what << " / " << f;
  }
}

void expectDynamicsRejected(double h, double kappa, std::initializer_list<std::string> fragments) {
  expectRejected([&] { validateDynamics(h, kappa); }, fragments);
}

// The gains the update multiplies by, all normal doubles at an accepted (h, kappa).
void expectNormalGains(double h, double kappa) {
  EXPECT_NO_THROW(validateDynamics(h, kappa)) << "h " << h << " kappa " << kappa;
  const VariationalCoefficients c(h, kappa);
  for (double gain : {c.decay, c.positionGain, c.gradientGain, c.startGain}) {
    EXPECT_TRUE(std::isnormal(gain)) << gain << " at h " << h << " kappa " << kappa;
  }
}

TEST(Limits, ConstantsAreTheBoundariesOfDoubleArithmetic) {
  // Each constant against its definition, from <cfloat> and <cstdint> (not from the code).
  EXPECT_TRUE(std::isfinite(2.0 * limits::kMaxTimeStep * limits::kMaxTimeStep));
  EXPECT_FALSE(std::isfinite(2.0 * up(limits::kMaxTimeStep) * up(limits::kMaxTimeStep)));
  EXPECT_GE(std::exp(-limits::kMaxDampingTimeStep), DBL_MIN);
  EXPECT_LT(std::exp(-up(limits::kMaxDampingTimeStep)), DBL_MIN);
  EXPECT_LT(limits::kMaxDampingTimeStep, std::log(DBL_MAX));  // so e^{kappa h} is finite too
  EXPECT_EQ(limits::kSmallestGain, DBL_MIN);
  EXPECT_EQ(limits::kMaxSteps, std::int64_t{1} << 53);
  EXPECT_EQ(static_cast<double>(limits::kMaxSteps - 1) + 1.0, static_cast<double>(limits::kMaxSteps));
  EXPECT_EQ(limits::kMaxPacingSeconds, static_cast<double>(INT32_MAX));
}

TEST(Limits, TimeStepAndKappaSignAndFiniteness) {
  expectDynamicsRejected(0.0, 1.0, {"time_step: must be finite and > 0, got 0"});
  expectDynamicsRejected(-0.1, 1.0, {"time_step: must be finite and > 0, got -0.1"});
  expectDynamicsRejected(NAN, 1.0, {"time_step: must be finite", "got nan"});
  expectDynamicsRejected(HUGE_VAL, 1.0, {"time_step: must be finite", "got inf"});
  expectDynamicsRejected(0.01, -2.0, {"kappa: must be finite and >= 0, got -2"});
  expectDynamicsRejected(0.01, NAN, {"kappa: must be finite", "got nan"});
  expectDynamicsRejected(0.01, HUGE_VAL, {"kappa: must be finite", "got inf"});
  expectNormalGains(0.01, 0.0);  // undamped
}

TEST(Limits, TimeStepWhoseSquareOverflows) {
  expectDynamicsRejected(1e200, 0.0, {"time_step: must be <= 9.480751908109176e+153 s", "got 1e+200"});
  expectDynamicsRejected(up(limits::kMaxTimeStep), 0.0, {"time_step: must be <="});
  expectNormalGains(limits::kMaxTimeStep, 0.0);
}

TEST(Limits, KappaTimesTimeStepWhoseExponentialOverflows) {
  // The case: e^{kappa h} = inf, every gain 0, agents frozen at their start.
  expectDynamicsRejected(0.01, 1e200, {"kappa * time_step: must be <= 708.3964185322641",
                                       "got 1e+200 * 0.01 = 1e+198"});
  expectDynamicsRejected(1.0, up(limits::kMaxDampingTimeStep), {"kappa * time_step: must be <="});
  expectDynamicsRejected(1e10, 1e-7, {"kappa * time_step"});  // 1000: e^{-1000} = 0
  expectNormalGains(1.0, limits::kMaxDampingTimeStep);
}

TEST(Limits, GainsThatWouldBeDenormal) {
  // kappa = 0: 2h^2/(1 + e^0) = h^2, normal from the smallest h with h h >= DBL_MIN on.
  double hMin = std::sqrt(DBL_MIN);
  while (hMin * hMin >= DBL_MIN) hMin = down(hMin);
  while (hMin * hMin < DBL_MIN) hMin = up(hMin);
  expectNormalGains(hMin, 0.0);
  expectDynamicsRejected(down(hMin), 0.0, {"time_step: too small, the gain 2h^2/(1 + e^{kappa h})",
                                           "must be >= 2.2250738585072014e-308"});
  expectDynamicsRejected(1e-170, 0.0, {"got h = 1e-170 with kappa = 0"});  // h^2 = 0
  // kappa h within its limit, but h^2 small enough that 2h^2/(1 + e^{kappa h}) is denormal:
  // 0.5 e^{-708} ~ 1.7e-308.
  expectDynamicsRejected(0.5, 1416.0, {"time_step: too small", "got h = 0.5 with kappa = 1416"});
  expectNormalGains(1.0, 708.0);
}

TEST(Limits, KappaRangeIsTheExactEdgeOfTheCheck) {
  for (double h : {1.0, 0.5, 0.02, 0.014, 0.01, 1e-3, 1e-100}) {
    const double k = maxDampingGain(h);
    EXPECT_NO_THROW(validateDynamics(h, k)) << "h " << h;
    EXPECT_THROW(validateDynamics(h, up(k)), InvalidInput) << "h " << h;
  }
  // At h = 1 the limit on kappa h governs; at h = 0.02 the gain 2h^2/(1 + e^{kappa h}) underflows
  // first (kappa h <= ln(2 h^2 / DBL_MIN - 1) ~ 701.3 < 708.4).
  EXPECT_EQ(maxDampingGain(1.0), limits::kMaxDampingTimeStep);
  EXPECT_NEAR(maxDampingGain(0.02) * 0.02, std::log(2 * 0.02 * 0.02 / DBL_MIN - 1), 1e-9);
  EXPECT_THROW(maxDampingGain(0.0), InvalidInput);  // no range without a valid h
}

TEST(Limits, RefusedKappaNamesTheValueTheRangeAndTheKeptKappa) {
  for (double h : {1.0, 0.5, 0.02, 0.014, 0.01, 1e-3}) {
    const double k = maxDampingGain(h);
    EXPECT_FALSE(refuseDampingGain(h, 0.0, 4.0, "~kappa"));
    EXPECT_FALSE(refuseDampingGain(h, k, 4.0, "~kappa"));
    for (double bad : {-5.0, -DBL_MIN, up(k), HUGE_VAL, std::nan("")}) {
      const auto line = refuseDampingGain(h, bad, 4.0, "~kappa");
      ASSERT_TRUE(line) << bad;
      EXPECT_EQ(line->find('\n'), std::string::npos) << *line;
      EXPECT_NE(line->find(" refused, outside the accepted range [0, "), std::string::npos) << *line;
      EXPECT_NE(line->find("; kappa stays 4"), std::string::npos) << *line;
    }
    // The range's upper end is rounded down: accepted itself, and within 6 digits of the edge.
    const std::string line = *refuseDampingGain(h, -1.0, 4.0, "~kappa");
    const std::size_t from = line.find("[0, ") + 4;
    const double shown = std::stod(line.substr(from, line.find(']') - from));
    EXPECT_LE(shown, k) << line;
    EXPECT_GE(shown, k * (1.0 - 1e-5)) << line;
  }
  // ln(2 h^2 / DBL_MIN - 1) / h = 35063.276 at h = 0.02 (computed apart, in Python), rounded down.
  EXPECT_EQ(*refuseDampingGain(0.02, -5.0, 4.0, "~kappa"),
            "~kappa: -5 refused, outside the accepted range [0, 35063.2] 1/s at time step h = 0.02 s; "
            "kappa stays 4");
  EXPECT_EQ(formatRounded(0.1 + 0.02), "0.12");  // not its shortest text 0.12000000000000001
}

TEST(Limits, Steps) {
  expectRejected([] { validateSteps(-1, false); }, {"steps: must be between 0 and 9007199254740992", "got -1"});
  expectRejected([] { validateSteps(limits::kMaxSteps + 1, false); }, {"steps: must be between"});
  expectRejected([] { validateSteps(0, true, "--steps"); }, {"--steps: must be >= 1", "got 0"});
  EXPECT_NO_THROW(validateSteps(0, false));  // unbounded ROS run
  EXPECT_NO_THROW(validateSteps(1, true));
  EXPECT_NO_THROW(validateSteps(limits::kMaxSteps, true));
}

TEST(Limits, RealTimeFactor) {
  const auto rejected = [](double factor, double h, std::initializer_list<std::string> fragments) {
    expectRejected([&] { validateRealTimeFactor(factor, h); }, fragments);
  };
  rejected(HUGE_VAL, 0.01, {"real_time_factor: must be finite and >= 0", "got inf"});
  rejected(NAN, 0.01, {"real_time_factor: must be finite", "got nan"});
  rejected(-1.0, 0.01, {"real_time_factor: must be finite and >= 0", "got -1"});
  // Pacing sleep h / factor beyond a ROS duration's int32 seconds.
  rejected(1.0, 1e10, {"real_time_factor: the pacing", "must be <= 2147483647 s", "got 1e+10 / 1 = 1e+10 s"});
  rejected(1e-300, 0.01, {"real_time_factor: the pacing"});
  rejected(down(1.0), limits::kMaxPacingSeconds, {"real_time_factor: the pacing"});
  expectRejected([] { validateRealTimeFactor(-1.0, 0.01, "~real_time_factor"); }, {"~real_time_factor: must"});
  EXPECT_NO_THROW(validateRealTimeFactor(0.0, 1e10));  // not paced: any h
  EXPECT_NO_THROW(validateRealTimeFactor(1.0, limits::kMaxPacingSeconds));
  EXPECT_NO_THROW(validateRealTimeFactor(1e300, 0.01));
}

TEST(Limits, ScenarioFileValuesGoThroughTheSameChecks) {
  expectError(replaced(valid(), "time_step: 0.01", "time_step: 1e200"),
              {"time_step: must be <= 9.480751908109176e+153 s", "got 1e+200"});
  expectError(replaced(valid(), "kappa: 1.0", "kappa: 1e200"),
              {"kappa * time_step: must be <= 708.3964185322641", "got 1e+200 * 0.01"});
  expectError(replaced(valid(), "time_step: 0.01", "time_step: 1e-170"), {"time_step: too small"});
  expectError(replaced(valid(), "steps: 10", "steps: 9007199254740993"), {"steps: must be between"});
  // At the boundary: accepted (kappa h = 708 with h = 1), with the stability warning.
  const Scenario s =
      parseScenario(replaced(replaced(valid(), "time_step: 0.01", "time_step: 1"), "kappa: 1.0", "kappa: 708"),
                    "file.yaml");
  EXPECT_EQ(s.dampingGain * s.timeStep, 708.0);
}

TEST(Overrides, ReRunTheValidationUnderTheFlagsNames) {
  const Scenario file = parseScenario(valid(), "file.yaml");
  ASSERT_TRUE(file.warnings.empty());
  const auto rejected = [&](const ScenarioOverrides& o, std::initializer_list<std::string> fragments) {
    Scenario s = file;
    expectRejected([&] { applyOverrides(s, o, /*requireBoundedSteps=*/true); }, fragments);
  };
  ScenarioOverrides o;
  o.dampingGain = 1e200;
  rejected(o, {"--kappa * time_step: must be <= 708.3964185322641"});
  o = {};
  o.timeStep = 1e200;
  rejected(o, {"--time-step: must be <= 9.480751908109176e+153 s"});
  o = {};
  o.timeStep = -1.0;
  rejected(o, {"--time-step: must be finite and > 0, got -1"});
  o = {};
  o.steps = 0;
  rejected(o, {"--steps: must be >= 1"});

  // The stability warning is recomputed for the overridden h, and names the flag.
  Scenario s = file;
  o = {};
  o.timeStep = 2.0;
  o.dampingGain = 0.0;
  applyOverrides(s, o, true);
  EXPECT_EQ(s.timeStep, 2.0);
  EXPECT_EQ(s.dampingGain, 0.0);
  EXPECT_EQ(s.steps, 10);  // not overridden: the file's value
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0].rfind("--time-step: h = 2 exceeds the linear stability limit", 0), 0u) << s.warnings[0];
  // ... and disappears when an override brings h back below the limit.
  o.timeStep = 0.01;
  applyOverrides(s, o, true);
  EXPECT_TRUE(s.warnings.empty());
}

}  // namespace
}  // namespace vf
