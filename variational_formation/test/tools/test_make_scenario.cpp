// make_scenario: every shape loads with the package's loader and is rigid at sizes up to 200
// agents, with the stated spacing and a seeded perturbation of the stated size; the file
// round-trips exactly; bad arguments are one line with exit status 2; a generated 50-agent
// formation converges in simulate with the defaults.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/generators/formation_generators.hpp"
#include "variational_formation/tools/make_scenario_cli.hpp"
#include "variational_formation/tools/simulate_cli.hpp"

namespace vf {
namespace {

struct CliResult {
  int status;
  std::string out;
  std::string err;
};

CliResult run(int (*cli)(int, const char* const*, std::ostream&, std::ostream&),
              std::vector<std::string> args) {
  args.insert(args.begin(), "tool");
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  const int status = cli(static_cast<int>(argv.size()), argv.data(), out, err);
  return {status, out.str(), err.str()};
}

CliResult makeScenario(const std::vector<std::string>& args) { return run(runMakeScenarioCli, args); }

std::string tempPath(const std::string& name) { return ::testing::TempDir() + "vf_make_" + name; }

/// Generates through the CLI into a file and loads it with the package's loader.
Scenario generateAndLoad(const std::vector<std::string>& args, const std::string& file) {
  std::vector<std::string> all = args;
  all.insert(all.end(), {"--out", tempPath(file)});
  const CliResult r = makeScenario(all);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  return loadScenario(tempPath(file));
}

std::vector<double> edgeLengths(const Scenario& s) {
  std::vector<double> lengths;
  for (const auto& [i, j] : s.edges) {
    lengths.push_back((s.desiredPositions.col(i) - s.desiredPositions.col(j)).norm());
  }
  return lengths;
}

double minPairwiseDistance(const Positions& q) {
  double best = INFINITY;
  for (Eigen::Index i = 0; i < q.cols(); ++i) {
    for (Eigen::Index j = i + 1; j < q.cols(); ++j) best = std::min(best, (q.col(i) - q.col(j)).norm());
  }
  return best;
}

/// Loads without warnings (neither "not rigid" nor "h too large"), is infinitesimally rigid by
/// the core's rank test on the loaded file, and is minimally rigid iff `minimal`.
void expectRigid(const Scenario& s, int agents, std::size_t edges, bool minimal) {
  EXPECT_EQ(s.agentCount(), agents);
  EXPECT_EQ(s.edges.size(), edges);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  const Formation f = makeFormation(s);
  EXPECT_TRUE(f.isInfinitesimallyRigid(s.desiredPositions)) << s.name;
  EXPECT_EQ(f.isMinimallyRigid(s.desiredPositions), minimal) << s.name;
}

const double kSqrt2 = std::sqrt(2.0);

TEST(MakeScenario, GridsAreRigidWithTheStatedSpacing) {
  const double spacing = 0.7;
  // (rows, cols): 6, 20, 100 and 200 agents; 2 x C is minimally rigid.
  for (const auto& [rows, cols] : std::vector<std::pair<int, int>>{{2, 3}, {4, 5}, {10, 10}, {10, 20}, {2, 100}}) {
    const Scenario s = generateAndLoad({"--shape", "grid", "--rows", std::to_string(rows), "--cols",
                                        std::to_string(cols), "--spacing", "0.7"},
                                       "grid.yaml");
    SCOPED_TRACE(s.name);
    EXPECT_EQ(s.dimension, 2);
    expectRigid(s, rows * cols, static_cast<std::size_t>(3 * rows * cols - 2 * rows - 2 * cols + 1),
                rows == 2 || cols == 2);
    for (double l : edgeLengths(s)) {
      EXPECT_TRUE(std::abs(l - spacing) < 1e-12 || std::abs(l - spacing * kSqrt2) < 1e-12) << l;
    }
    EXPECT_NEAR(minPairwiseDistance(s.desiredPositions), spacing, 1e-12);
  }
}

TEST(MakeScenario, RingsWithTheDefaultChordIsRigidAtEverySize) {
  const double spacing = 1.3;
  for (int n : {3, 4, 5, 6, 7, 20, 50, 100, 200}) {
    const Scenario s = generateAndLoad({"--shape", "ring", "--agents", std::to_string(n), "--spacing", "1.3"},
                                       "ring.yaml");
    SCOPED_TRACE(s.name);
    // Ring edges plus chords to the second neighbour, without duplicates: K3, K4, then 2n.
    const std::size_t edges = n == 3 ? 3 : (n == 4 ? 6 : static_cast<std::size_t>(2 * n));
    expectRigid(s, n, edges, n == 3);
    // Neighbours on the ring are exactly `spacing` apart and everyone is on one circle.
    const double radius = s.desiredPositions.col(0).norm();
    for (int i = 0; i < n; ++i) {
      EXPECT_NEAR((s.desiredPositions.col(i) - s.desiredPositions.col((i + 1) % n)).norm(), spacing, 1e-12);
      EXPECT_NEAR(s.desiredPositions.col(i).norm(), radius, 1e-12 * radius);
    }
    EXPECT_NEAR(minPairwiseDistance(s.desiredPositions), spacing, 1e-12);
  }
}

TEST(MakeScenario, RingWithoutChordsIsRefusedAsNotRigid) {
  const CliResult r = makeScenario({"--shape", "ring", "--agents", "8", "--chords", "0"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "make_scenario: error: --shape ring: the generated graph is not infinitesimally rigid "
                   "(rigidity rank 8, need 13); use --chords 1 or more\n");
  // More chords stay rigid (and no longer minimal).
  expectRigid(generateAndLoad({"--shape", "ring", "--agents", "12", "--chords", "3"}, "ring3.yaml"), 12, 48, false);
}

TEST(MakeScenario, LatticesAreRigidWithTheStatedSpacing) {
  const double spacing = 2.5;
  // (rows, cols, layers): 8, 60, 100 and 200 agents; 2 x 2 x 2 is a cube with one diagonal
  // per face, 18 = 3 * 8 - 6 edges.
  for (const auto& [r, c, l] : std::vector<std::array<int, 3>>{{2, 2, 2}, {3, 4, 5}, {4, 5, 5}, {5, 5, 8}}) {
    const Scenario s = generateAndLoad({"--shape", "lattice", "--rows", std::to_string(r), "--cols",
                                        std::to_string(c), "--layers", std::to_string(l), "--spacing", "2.5"},
                                       "lattice.yaml");
    SCOPED_TRACE(s.name);
    EXPECT_EQ(s.dimension, 3);
    const std::size_t axis = static_cast<std::size_t>((r - 1) * c * l + r * (c - 1) * l + r * c * (l - 1));
    const std::size_t faces =
        static_cast<std::size_t>((r - 1) * (c - 1) * l + (r - 1) * c * (l - 1) + r * (c - 1) * (l - 1));
    expectRigid(s, r * c * l, axis + faces, r == 2 && c == 2 && l == 2);
    for (double length : edgeLengths(s)) {
      EXPECT_TRUE(std::abs(length - spacing) < 1e-12 || std::abs(length - spacing * kSqrt2) < 1e-12) << length;
    }
    EXPECT_NEAR(minPairwiseDistance(s.desiredPositions), spacing, 1e-12);
  }
}

TEST(MakeScenario, HennebergConstructionsAreMinimallyRigid) {
  const double spacing = 0.8;
  for (int d : {2, 3}) {
    for (int n : {d + 1, 20, 100, 200}) {
      const Scenario s = generateAndLoad({"--shape", "henneberg", "--agents", std::to_string(n), "--dimension",
                                          std::to_string(d), "--seed", "42", "--spacing", "0.8"},
                                         "henneberg.yaml");
      SCOPED_TRACE(s.name);
      EXPECT_EQ(s.dimension, d);
      expectRigid(s, n, static_cast<std::size_t>(d * n - d * (d + 1) / 2), true);
      // At least `spacing` between any two agents; each agent after the simplex is within
      // 2 spacing of an earlier one.
      EXPECT_GE(minPairwiseDistance(s.desiredPositions), spacing * (1.0 - 1e-12));
      for (int k = d + 1; k < n; ++k) {
        double nearest = INFINITY;
        for (int j = 0; j < k; ++j) {
          nearest = std::min(nearest, (s.desiredPositions.col(k) - s.desiredPositions.col(j)).norm());
        }
        EXPECT_LT(nearest, 2.0 * spacing) << "agent " << k;
      }
    }
  }
  // Another seed, another shape.
  EXPECT_NE(hennebergConstruction(30, 2, 1, 1.0).desiredPositions,
            hennebergConstruction(30, 2, 2, 1.0).desiredPositions);
}

TEST(MakeScenario, PerturbationIsSeededUniformOfTheStatedSize) {
  const double sigma = 0.25;
  const Positions desired = Positions::Constant(3, 400, 5.0);
  const Eigen::ArrayXXd u = (perturbedPositions(desired, sigma, 7) - desired).array();
  const double samples = static_cast<double>(u.size());  // 1200
  // Uniform on [-sigma, sigma]: bounded by sigma, reaching close to it (P(all < 0.98 sigma) =
  // 0.98^1200 < 1e-10), mean 0 and variance sigma^2 / 3, each within 5 standard errors.
  EXPECT_LE(u.abs().maxCoeff(), sigma);
  EXPECT_GT(u.abs().maxCoeff(), 0.98 * sigma);
  EXPECT_LT(std::abs(u.mean()), 5.0 * sigma / std::sqrt(3.0 * samples));
  const double variance = (u * u).mean();
  EXPECT_NEAR(variance, sigma * sigma / 3.0, 5.0 * sigma * sigma * std::sqrt(4.0 / 45.0 / samples));
  // Deterministic for a seed, different for another; 0 is no perturbation.
  EXPECT_EQ(perturbedPositions(desired, sigma, 7), perturbedPositions(desired, sigma, 7));
  EXPECT_NE(perturbedPositions(desired, sigma, 7), perturbedPositions(desired, sigma, 8));
  EXPECT_EQ(perturbedPositions(desired, 0.0, 7), desired);
  EXPECT_THROW(perturbedPositions(desired, -0.1, 7), InvalidInput);
  EXPECT_THROW(perturbedPositions(desired, NAN, 7), InvalidInput);
}

TEST(MakeScenario, CliStartsAtThePerturbationOfItsSeed) {
  const std::vector<std::string> args = {"--shape", "lattice", "--rows", "2", "--cols", "3", "--layers", "2",
                                         "--spacing", "3", "--perturb", "0.25", "--seed", "7"};
  const CliResult a = makeScenario(args), b = makeScenario(args);
  ASSERT_EQ(a.status, 0) << a.err;
  EXPECT_EQ(a.out, b.out);  // the same seed gives the same file
  const Scenario s = parseScenario(a.out, "stdout");
  EXPECT_EQ(s.initialPositions, perturbedPositions(s.desiredPositions, 0.25, 7));
  EXPECT_TRUE(s.initialVelocities.isZero(0.0));
  // Without --perturb and --seed: 0.1 * spacing, seed 1.
  const Scenario byDefault = parseScenario(
      makeScenario({"--shape", "lattice", "--rows", "2", "--cols", "3", "--layers", "2", "--spacing", "3"}).out,
      "stdout");
  EXPECT_EQ(byDefault.initialPositions, perturbedPositions(byDefault.desiredPositions, 0.1 * 3.0, 1));
  EXPECT_EQ(byDefault.desiredPositions, s.desiredPositions);
}

TEST(MakeScenario, PerturbationDrawsTheStandardsMersenneTwister) {
  // The C++ standard fixes the 10000th output of a default-seeded (5489) mt19937_64 at
  // 9981545732273789042; the noise is 2 (x >> 11) 2^-53 - 1 of it, for sigma = 1 from zero.
  const Positions u = perturbedPositions(Positions::Zero(1, 10000), 1.0, 5489);
  EXPECT_EQ(u(0, 9999), 2.0 * static_cast<double>(9981545732273789042ULL >> 11) * 0x1.0p-53 - 1.0);
}

TEST(MakeScenario, FileRoundTripsExactly) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--shape", "henneberg", "--agents", "30", "--dimension", "3", "--seed", "5",
                                 "--spacing", "0.3", "--perturb", "0.0123", "--kappa", "1.7", "--time-step",
                                 "0.0031", "--steps", "77", "--name", "cloud"},
        std::vector<std::string>{"--shape", "ring", "--agents", "9", "--spacing", "0.1"}}) {
    const std::string file = tempPath("roundtrip.yaml");
    std::vector<std::string> withOut = args;
    withOut.insert(withOut.end(), {"--out", file});
    const CliResult written = makeScenario(withOut), printed = makeScenario(args);
    ASSERT_EQ(written.status, 0) << written.err;
    std::ifstream in(file);
    std::stringstream text;
    text << in.rdbuf();
    // --out writes what stdout gets, after the comment line with the command.
    EXPECT_EQ(text.str().substr(text.str().find('\n')), printed.out.substr(printed.out.find('\n')));

    const Scenario s = loadScenario(file);
    // Writing the loaded scenario gives the same numbers, and loading that the same doubles.
    std::ostringstream again;
    writeScenarioYaml(s, {}, again);
    const Scenario t = parseScenario(again.str(), "again");
    EXPECT_EQ(t.name, s.name);
    EXPECT_EQ(t.dimension, s.dimension);
    EXPECT_EQ(t.dampingGain, s.dampingGain);
    EXPECT_EQ(t.timeStep, s.timeStep);
    EXPECT_EQ(t.steps, s.steps);
    EXPECT_EQ(t.initialPositions, s.initialPositions);
    EXPECT_EQ(t.initialVelocities, s.initialVelocities);
    EXPECT_EQ(t.desiredPositions, s.desiredPositions);
    EXPECT_EQ(t.edges, s.edges);
    EXPECT_EQ(text.str().substr(text.str().find("\nname:") + 1), again.str());
  }
  // The last file (the ring) has the defaults: h accepted by the stability advice.
  const Scenario ring = loadScenario(tempPath("roundtrip.yaml"));
  EXPECT_EQ(ring.name, "ring_9");
  EXPECT_EQ(ring.timeStep, 0.005);
  EXPECT_EQ(ring.dampingGain, 2.0);
  EXPECT_EQ(ring.steps, 4000);
  // The generator's own doubles come back exactly.
  EXPECT_EQ(parseScenario(makeScenario({"--shape", "henneberg", "--agents", "30", "--dimension", "3", "--seed",
                                        "5", "--spacing", "0.3"}).out, "x").desiredPositions,
            hennebergConstruction(30, 3, 5, 0.3).desiredPositions);
}

// The scale rostest's scenario (config/lattice48.yaml) is make_scenario's output, byte for byte,
// for the command line in its first line.
TEST(MakeScenario, RegeneratesTheScaleTestScenario) {
  std::ifstream file(std::string(VF_SOURCE_DIR) + "/config/lattice48.yaml");
  ASSERT_TRUE(file.good());
  const std::string content((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  const std::string prefix = "# Generated by: make_scenario ";
  ASSERT_EQ(content.rfind(prefix, 0), 0u);
  std::istringstream line(content.substr(prefix.size(), content.find('\n') - prefix.size()));
  std::vector<std::string> args;
  for (std::string word; line >> word;) args.push_back(word);
  const CliResult r = makeScenario(args);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, content);
}

TEST(MakeScenario, TimeStepAgainstTheStabilityAdvice) {
  // Spacing 100 stiffens the formation 10^4-fold: the default h is refused, a given one warned.
  const CliResult refused = makeScenario({"--shape", "ring", "--agents", "10", "--spacing", "100"});
  EXPECT_EQ(refused.status, 2);
  EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  EXPECT_EQ(refused.err.rfind("make_scenario: error: --time-step: the default 0.005 s is not below", 0), 0u)
      << refused.err;
  const CliResult warned =
      makeScenario({"--shape", "ring", "--agents", "10", "--spacing", "100", "--time-step", "0.01"});
  EXPECT_EQ(warned.status, 0);
  EXPECT_NE(warned.err.find("make_scenario: warning: time_step: h = 0.01 exceeds"), std::string::npos)
      << warned.err;
  EXPECT_EQ(makeScenario({"--shape", "ring", "--agents", "10", "--spacing", "100", "--time-step", "0.001"}).err, "");
  // A step the user chose is theirs, as in every tool that loads a scenario (one warning, the
  // file written): issue 23's `--time-step 2`.
  const CliResult chosen = makeScenario({"--shape", "grid", "--rows", "3", "--cols", "3", "--time-step", "2"});
  EXPECT_EQ(chosen.status, 0) << chosen.err;
  EXPECT_EQ(std::count(chosen.err.begin(), chosen.err.end(), '\n'), 1) << chosen.err;
  EXPECT_EQ(chosen.err.rfind("make_scenario: warning: time_step: h = 2 exceeds the linear stability limit", 0), 0u)
      << chosen.err;
  EXPECT_NE(chosen.out.find("\ntime_step: 2\n"), std::string::npos) << chosen.out;
}

void expectBadInput(const std::vector<std::string>& args, const std::string& fragment) {
  const CliResult r = makeScenario(args);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("make_scenario: error: " + fragment, 0), 0u) << r.err << " / " << fragment;
}

TEST(MakeScenario, BadArgumentsAreOneLineWithStatusTwo) {
  const std::vector<std::string> ring6 = {"--shape", "ring", "--agents", "6"};
  const auto ring = [&ring6](std::vector<std::string> extra) {
    extra.insert(extra.begin(), ring6.begin(), ring6.end());
    return extra;
  };
  // (arguments, the start of the message after "make_scenario: error: ")
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{}, "--shape: required"},
      {{"--shape", "star"}, "--shape: unknown shape 'star'"},
      {{"--shape"}, "--shape: expects 1 value"},
      {{"--shape", "grid", "--rows", "3"}, "--cols: required"},
      {{"--shape", "grid", "--rows", "3", "--cols"}, "--cols: expects 1 value"},
      {{"--shape", "grid", "--rows", "-3", "--cols", "3"}, "--rows: must be between 1 and 2000, got -3"},
      {{"--shape", "grid", "--rows", "1", "--cols", "3"}, "--rows: must be >= 2, got 1"},
      {{"--shape", "grid", "--rows", "three", "--cols", "3"}, "--rows: expected an integer"},
      {{"--shape", "grid", "--rows", "3", "--cols", "2.5"}, "--cols: expected an integer"},
      {{"--shape", "grid", "--rows", "100", "--cols", "100"}, "--rows x --cols: 10000 agents, more than 2000"},
      {{"--shape", "grid", "--rows", "3", "--cols", "3", "--agents", "9"}, "--agents: not used by --shape grid"},
      {{"--shape", "ring"}, "--agents: required"},
      {{"--shape", "ring", "--agents", "2"}, "--agents: must be >= 3, got 2"},
      {ring({"--chords", "5"}), "--chords: must be between 0 and agents - 2 = 4"},
      {ring({"--chords", "-1"}), "--chords: must be between 0 and 2000"},
      {{"--shape", "lattice", "--rows", "2", "--cols", "2"}, "--layers: required"},
      {{"--shape", "lattice", "--rows", "2", "--cols", "2", "--layers", "1"}, "--layers: must be >= 2"},
      {{"--shape", "henneberg", "--agents", "10"}, "--dimension: required"},
      {{"--shape", "henneberg", "--agents", "10", "--dimension", "4"}, "--dimension: must be between 2 and 3"},
      {{"--shape", "henneberg", "--agents", "3", "--dimension", "3"}, "--agents: must be >= 4, got 3"},
      {ring({"--spacing", "-1"}), "--spacing: must be > 0"},
      {ring({"--spacing", "wide"}), "--spacing: expected a finite number"},
      {ring({"--perturb", "-0.1"}), "--perturb: must be >= 0"},
      {ring({"--perturb", "nan"}), "--perturb: expected a finite number"},
      {ring({"--seed", "-1"}), "--seed: must be between 0"},
      {ring({"--kappa", "-2"}), "--kappa: must be >= 0"},
      {ring({"--time-step", "0"}), "--time-step: must be > 0"},
      {ring({"--steps", "0"}), "--steps: must be between 1"},
      {ring({"--name", "a: b"}), "--name: must be a plain"},
      {ring({"--name", "Null"}), "--name: must be a plain"},
      {ring({"--out", "/nonexistent/dir/s.yaml"}), "--out: cannot write"},
      {ring({"--bogus"}), "--bogus: unknown flag"},
      {ring({"--agents", "7"}), "--agents: given more than once"},
  };
  for (const auto& [args, fragment] : cases) expectBadInput(args, fragment);
}

TEST(MakeScenario, HelpExitsZero) {
  const CliResult r = makeScenario({"--help"});
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("--shape grid"), std::string::npos);
}

/// Final positions and velocities ((q_N - q_{N-1}) / h) from a simulate traj.csv.
std::pair<Positions, Positions> finalState(const std::string& traj, const Scenario& s) {
  std::ifstream in(traj);
  std::vector<std::string> rows;
  for (std::string line; std::getline(in, line);) rows.push_back(line);
  const int n = s.agentCount();
  Positions last(s.dimension, n), before(s.dimension, n);
  for (int k = 0; k < 2 * n; ++k) {
    double step, t, agent, xyz[3];
    const std::string& row = rows[rows.size() - 2 * n + k];
    EXPECT_EQ(std::sscanf(row.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf", &step, &t, &agent, &xyz[0], &xyz[1], &xyz[2]), 6);
    EXPECT_EQ(step, static_cast<double>(k < n ? s.steps - 1 : s.steps)) << row;
    Positions& q = k < n ? before : last;
    for (int a = 0; a < s.dimension; ++a) q(a, static_cast<int>(agent)) = xyz[a];
  }
  return {last, (last - before) / s.timeStep};
}

TEST(MakeScenario, FiftyAgentsConvergeInSimulateWithTheDefaults) {
  // Defaults: kappa 2, h 0.005 s, 4000 steps, start perturbed by 0.1 spacing. (Minimally
  // rigid Henneberg graphs and rings have soft modes and need many more steps.)
  for (const std::vector<std::string>& shape :
       {std::vector<std::string>{"--shape", "grid", "--rows", "5", "--cols", "10"},
        std::vector<std::string>{"--shape", "lattice", "--rows", "2", "--cols", "5", "--layers", "5"}}) {
    const Scenario s = generateAndLoad(shape, "fifty.yaml");
    SCOPED_TRACE(s.name);
    ASSERT_EQ(s.agentCount(), 50);
    const Formation f = makeFormation(s);
    ASSERT_FALSE(f.isCongruent(s.initialPositions, s.initialVelocities));  // there is work to do
    const std::string traj = tempPath("fifty.csv");
    const CliResult r = run(runSimulateCli, {"--scenario", tempPath("fifty.yaml"), "--out", traj});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err, "");
    const auto [q, v] = finalState(traj, s);
    EXPECT_TRUE(f.isCongruent(q, v)) << "max edge error " << f.maxDistanceError(q);
  }
}

}  // namespace
}  // namespace vf
