// simulate with a manoeuvre: the scenario's schedule and the equivalent commands file give the
// same output byte for byte, tracking columns, and one-line errors (exit status 2) for every kind
// of bad schedule and bad commands file.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "variational_formation_core/model/scenario.hpp"
#include "simulate_test_support.hpp"

namespace vf {
namespace {

using namespace test;  // NOLINT: the shared simulate helpers (simulate_test_support.hpp)

std::string tempPath(const std::string& name) { return ::testing::TempDir() + "vf_manoeuvre_" + name; }

std::string write(const std::string& name, const std::string& text) {
  const std::string path = tempPath(name);
  std::ofstream(path) << text;
  return path;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The hexagon scenario without its manoeuvre, with `manoeuvre` appended.
std::string hexagonWith(const std::string& manoeuvre, int dimension = 2) {
  std::string text = slurp(kConfig + (dimension == 2 ? "hexagon_manoeuvre.yaml" : "tetrahedron.yaml"));
  const std::size_t at = text.find("manoeuvre:\n");
  if (at != std::string::npos) text = text.substr(0, at);
  return text + manoeuvre;
}

void expectBadSchedule(const std::string& name, const std::string& manoeuvre, const std::string& fragment,
                       int dimension = 2) {
  const std::string sc = write(name + ".yaml", hexagonWith(manoeuvre, dimension));
  expectBadInput({"--scenario", sc, "--out", tempPath("bad.csv")}, fragment);
}

TEST(SimulateManoeuvre, ScheduleAndItsCommandsFileGiveIdenticalOutput) {
  const std::string scenarioPath = kConfig + "hexagon_manoeuvre.yaml";
  const Scenario scenario = loadScenario(scenarioPath);
  std::ostringstream csv;
  writeCommands(csv, scheduleFromSegments(scenario.manoeuvre, scenario.timeStep));
  const std::string commands = write("schedule.csv", csv.str());
  EXPECT_NE(csv.str().find("\n400,1,0,0,0,0,0,1\n"), std::string::npos) << csv.str();

  const std::string t1 = tempPath("t1.csv"), m1 = tempPath("m1.csv"), t2 = tempPath("t2.csv"), m2 = tempPath("m2.csv");
  ASSERT_EQ(simulate({"--scenario", scenarioPath, "--out", t1, "--metrics", m1}).status, 0);
  // The commands file replaces the schedule: give it a scenario with a different schedule.
  const std::string other = write("other.yaml", hexagonWith("manoeuvre:\n  - {velocity: [0, -3]}\n"));
  const CliResult r = simulate({"--scenario", other, "--out", t2, "--metrics", m2, "--commands", commands,
                                "--steps", "3000"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(t1), slurp(t2));
  EXPECT_EQ(slurp(m1), slurp(m2));
  // ...and it does move: the last row's centroid velocity is the last segment's v* = (-1, 0).
  std::istringstream rows(slurp(m1));
  std::string line, last;
  while (std::getline(rows, line)) last = line;
  std::vector<double> x;
  std::istringstream fields(last);
  for (std::string f; std::getline(fields, f, ',');) x.push_back(std::stod(f));
  ASSERT_EQ(x.size(), 18u);  // the 17 columns and shape_error
  EXPECT_NEAR(x[10], -1.0, 1e-6);
  EXPECT_NEAR(x[11], 0.0, 1e-6);
  EXPECT_NEAR(x[15], 0.0, 1e-6);   // no rotation in the last segment
  EXPECT_NEAR(x[16], 0.0, 1e-6);   // scale 1.5 reached
  EXPECT_LT(x[3], 1e-5);           // edges at 1.5 d_ij
  EXPECT_LT(x[17], 1e-4);          // and every pair: the shape is 1.5 q*
}

TEST(SimulateManoeuvre, OnlyWithTheVariationalMethodAndWithoutDelay) {
  const std::string sc = kConfig + "hexagon_manoeuvre.yaml";
  expectBadInput({"--scenario", sc, "--out", tempPath("x.csv"), "--method", "rk4"}, "manoeuvre: only with --method vi");
  expectBadInput({"--scenario", sc, "--out", tempPath("x.csv"), "--delay-steps", "2"}, "manoeuvre: not with --delay-steps");
}

// One test per kind of bad schedule.
TEST(BadSchedule, UnknownKey) {
  expectBadSchedule("unknown", "manoeuvre:\n  - {until: 2, speed: [1, 0]}\n", "manoeuvre[0].speed: unknown field");
}
TEST(BadSchedule, WrongVectorLength) {
  expectBadSchedule("vlen", "manoeuvre:\n  - {until: 2, velocity: [1, 0, 0]}\n", "manoeuvre[0].velocity: expected 2 coordinates");
  expectBadSchedule("wlen2", "manoeuvre:\n  - {until: 2, angular_rate: [0, 0, 1]}\n",
                    "manoeuvre[0].angular_rate: expected a number (the rate about z in 2D)");
  expectBadSchedule("wlen3", "manoeuvre:\n  - {until: 2, angular_rate: [0, 1]}\n",
                    "manoeuvre[0].angular_rate: expected 3 coordinates", 3);
}
TEST(BadSchedule, UntilNotIncreasing) {
  expectBadSchedule("until", "manoeuvre:\n  - {until: 3}\n  - {until: 3, scale: 2}\n",
                    "manoeuvre[1].until: must be greater than manoeuvre[0].until = 3, got 3");
  expectBadSchedule("until0", "manoeuvre:\n  - {until: 0}\n", "manoeuvre[0].until: must be > 0 s");
  expectBadSchedule("untilmissing", "manoeuvre:\n  - {scale: 2}\n  - {until: 3}\n",
                    "manoeuvre[0].until: missing (only the last segment may omit it)");
}
TEST(BadSchedule, ScaleNotPositive) {
  expectBadSchedule("scale0", "manoeuvre:\n  - {until: 2, scale: 0}\n", "manoeuvre[0].scale: must be finite and > 0, got 0");
  expectBadSchedule("scaleneg", "manoeuvre:\n  - {until: 2}\n  - {scale: -1.5}\n", "manoeuvre[1].scale: must be finite and > 0, got -1.5");
}
TEST(BadSchedule, NonFiniteNumber) {
  expectBadSchedule("nan", "manoeuvre:\n  - {until: 2, velocity: [.nan, 0]}\n", "manoeuvre[0].velocity[0]: must be finite");
  expectBadSchedule("inf", "manoeuvre:\n  - {until: .inf}\n", "manoeuvre[0].until: must be finite");
  expectBadSchedule("winf", "manoeuvre:\n  - {until: 2, angular_rate: -.inf}\n", "manoeuvre[0].angular_rate: must be finite");
}
TEST(BadSchedule, NotAListOfMappings) {
  expectBadSchedule("notlist", "manoeuvre: {until: 2}\n", "manoeuvre: expected a non-empty list of segments");
  expectBadSchedule("notmap", "manoeuvre:\n  - 3\n", "manoeuvre[0]: expected a mapping");
}
TEST(BadSchedule, TurningTooFastPerStep) {
  expectBadSchedule("fast", "manoeuvre:\n  - {angular_rate: 11}\n", "manoeuvre[0].angular_rate: turns h |omega| = 0.11 rad per step");
}
TEST(BadSchedule, AnAgentThatCannotKnowItsCentroidOffsetCannotTurn) {
  // The hexagon without the chords: agent 0 keeps 2 neighbours, but drop edge [0, 1] and its
  // only edge [5, 0] does not point at the centroid.
  std::string text = hexagonWith("manoeuvre:\n  - {angular_rate: 0.5}\n");
  const std::string edges = "edges: [[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [5, 0], [0, 2], [0, 3], [0, 4]]";
  text.replace(text.find(edges), edges.size(), "edges: [[1, 2], [2, 3], [3, 4], [4, 5], [5, 0], [5, 1], [4, 1], [3, 1], [2, 4]]");
  const std::string sc = write("cannotturn.yaml", text);
  expectBadInput({"--scenario", sc, "--out", tempPath("x.csv")}, "manoeuvre: agent 0 cannot know its offset from the centroid");
}

TEST(SimulateManoeuvre, WarnsWhenTurningFasterThanHalfTheSoftestShapeMode) {
  // The hexagon's softest mode: 1.92 rad/s at scale 1. 0.9 rad/s is below half of it, 1.2 above.
  const std::string slow = write("slow.yaml", hexagonWith("manoeuvre:\n  - {angular_rate: 0.9}\n"));
  const std::string fast = write("fastwarn.yaml", hexagonWith("manoeuvre:\n  - {angular_rate: 1.2}\n"));
  const CliResult a = simulate({"--scenario", slow, "--out", tempPath("x.csv"), "--steps", "10"});
  const CliResult b = simulate({"--scenario", fast, "--out", tempPath("x.csv"), "--steps", "10"});
  EXPECT_EQ(a.status, 0);
  EXPECT_EQ(a.err.find("softest"), std::string::npos) << a.err;
  EXPECT_EQ(b.status, 0);
  EXPECT_NE(b.err.find("simulate: warning: manoeuvre[0].angular_rate: |omega| = 1.2 rad/s is above half the softest"),
            std::string::npos) << b.err;
}

// One test per kind of bad commands file.
void expectBadCommands(const std::string& name, const std::string& csv, const std::string& fragment) {
  const std::string path = write(name + ".csv", csv);
  expectBadInput({"--scenario", kConfig + "hexagon_manoeuvre.yaml", "--out", tempPath("x.csv"), "--commands", path},
                 path + ": " + fragment);
}
const std::string kHeader = "step,vx,vy,vz,wx,wy,wz,scale\n";

TEST(BadCommands, MissingFileAndBadHeader) {
  expectBadInput({"--scenario", kConfig + "hexagon_manoeuvre.yaml", "--out", tempPath("x.csv"), "--commands",
                  "/nonexistent/c.csv"}, "/nonexistent/c.csv: cannot open the commands file");
  expectBadCommands("header", "step,vx,vy\n0,1,0\n", "line 1: expected the header 'step,vx,vy,vz,wx,wy,wz,scale'");
  expectBadCommands("empty", kHeader, "no command rows after the header");
}
TEST(BadCommands, WrongColumnCount) {
  expectBadCommands("columns", kHeader + "0,1,0,0,0,0,0\n", "line 2: expected 8 columns");
}
TEST(BadCommands, StepsNotIncreasing) {
  expectBadCommands("steps", kHeader + "0,1,0,0,0,0,0,1\n10,0,1,0,0,0,0,1\n10,0,0,0,0,0,0,1\n",
                    "line 4: step: steps must increase, previous 10, got 10");
  expectBadCommands("negative", kHeader + "-1,1,0,0,0,0,0,1\n", "line 2: step: must be >= 0, got -1");
  expectBadCommands("fraction", kHeader + "1.5,1,0,0,0,0,0,1\n", "line 2: step: expected an integer, got '1.5'");
}
TEST(BadCommands, ScaleNotPositive) {
  expectBadCommands("scale", kHeader + "0,1,0,0,0,0,0,0\n", "line 2: scale: must be finite and > 0, got 0");
}
TEST(BadCommands, NonFiniteOrNotANumber) {
  expectBadCommands("nan", kHeader + "0,nan,0,0,0,0,0,1\n", "line 2: vx,vy,vz: must be finite");
  expectBadCommands("inf", kHeader + "0,0,0,0,0,0,inf,1\n", "line 2: wx,wy,wz: must be finite");
  expectBadCommands("text", kHeader + "0,fast,0,0,0,0,0,1\n", "line 2: vx: expected a number, got 'fast'");
}
TEST(BadCommands, ThirdDimensionInTwoDimensions) {
  expectBadCommands("vz", kHeader + "0,0,0,0.5,0,0,0,1\n", "line 2: vx,vy,vz: a 2D formation has no z velocity");
  expectBadCommands("wx", kHeader + "0,0,0,0,0.5,0,0,1\n", "line 2: wx,wy,wz: a 2D formation turns about z only");
}

}  // namespace
}  // namespace vf
