// The tools of issue 32: scenario_info's rigidity lines, make_scenario --graph (globally rigid
// graphs), assign_slots, and simulate's final line on the desired, a folded and an assigned run;
// issue 50: one verdict in every line of a run (mirror image, still settling, folded).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "variational_formation_core/model/rigidity.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation/tools/assign_slots_cli.hpp"
#include "variational_formation/tools/make_scenario_cli.hpp"
#include "variational_formation/tools/scenario_info_cli.hpp"
#include "variational_formation/tools/simulate_cli.hpp"
#include "simulate_test_support.hpp"

namespace vf {
namespace {

const std::string kConfig = std::string(VF_SOURCE_DIR) + "/config/";

using test::CliResult;

CliResult run(int (*cli)(int, const char* const*, std::ostream&, std::ostream&), std::vector<std::string> args) {
  return test::runCli(cli, std::move(args));
}

std::string tempPath(const std::string& name) { return ::testing::TempDir() + "vf_shape_" + name; }

std::string write(const std::string& name, const std::string& text) {
  const std::string path = tempPath(name);
  std::ofstream(path) << text;
  return path;
}

std::string lastLine(const std::string& text) {
  const std::size_t end = text.find_last_not_of('\n');
  const std::size_t start = text.rfind('\n', end);
  return text.substr(start == std::string::npos ? 0 : start + 1, end - (start == std::string::npos ? 0 : start + 1) + 1);
}

TEST(ScenarioInfo, SaysTheRigidityClassAndWarnsUnlessGloballyRigid) {
  const CliResult hexagon = run(runScenarioInfoCli, {"--scenario", kConfig + "hexagon.yaml"});
  EXPECT_EQ(hexagon.status, 0);
  EXPECT_EQ(hexagon.out, "agents 6\n");  // what the launch scripts read, unchanged
  EXPECT_EQ(hexagon.err,
            "scenario_info: graph: minimally rigid in 2D (6 agents, 9 edges; rigidity rank 9 of 9; 0 self-stresses)\n"
            "scenario_info: warning: the graph is not globally rigid: the formation can settle in another shape with "
            "every edge at its length (make_scenario --graph complete builds one that is; doc/scenarios.md says when "
            "knn is better)\n");
  const CliResult ring = run(runScenarioInfoCli, {"--scenario", kConfig + "ring7.yaml"});
  EXPECT_EQ(ring.status, 0);
  EXPECT_EQ(ring.err.rfind("scenario_info: graph: globally rigid in 2D (7 agents, 14 edges", 0), 0u) << ring.err;
  EXPECT_EQ(ring.err.find("warning"), std::string::npos) << ring.err;
}

// The shipped deployment: scattered starts, a globally rigid graph (its comment says so, and
// scenario_info), the safety filter; it must reach the desired shape in simulate, no two agents
// closer than the filter's radius.
TEST(HexagonDeploy, IsGloballyRigidAndReachesTheDesiredShapeWithAgentsApart) {
  std::ifstream file(kConfig + "hexagon_deploy.yaml");
  std::stringstream text;
  text << file.rdbuf();
  EXPECT_NE(text.str().find("globally rigid in 2D"), std::string::npos);
  const Scenario s = loadScenario(kConfig + "hexagon_deploy.yaml");
  ASSERT_TRUE(s.safety.has_value());
  EXPECT_EQ(classifyRigidity(makeFormation(s)).rigidityClass, RigidityClass::GloballyRigid);
  const CliResult info = run(runScenarioInfoCli, {"--scenario", kConfig + "hexagon_deploy.yaml"});
  EXPECT_EQ(info.status, 0);
  EXPECT_EQ(info.err.find("warning"), std::string::npos) << info.err;
  const CliResult r = run(runSimulateCli, {"--scenario", kConfig + "hexagon_deploy.yaml", "--out", "/dev/null"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(lastLine(r.out).rfind("formation: converged to the desired shape at step ", 0), 0u) << r.out;
  const std::size_t at = r.out.find("closest approach ");
  ASSERT_NE(at, std::string::npos) << r.out;
  EXPECT_GE(std::stod(r.out.substr(at + 17)), s.safety->radius * (1.0 - 1e-9)) << r.out;
}

Scenario generated(const std::vector<std::string>& flags, const std::string& file, std::string* comments = nullptr) {
  std::vector<std::string> args = flags;
  args.insert(args.end(), {"--out", tempPath(file)});
  const CliResult r = run(runMakeScenarioCli, args);
  EXPECT_EQ(r.status, 0) << r.err;
  if (comments) {
    std::ifstream in(tempPath(file));
    for (std::string line; std::getline(in, line) && line.rfind("#", 0) == 0;) *comments += line + "\n";
  }
  return loadScenario(tempPath(file));
}

TEST(MakeScenarioGraph, CompleteAndNearestNeighbourGraphsAreGloballyRigid) {
  const Scenario complete = generated({"--shape", "ring", "--agents", "6", "--graph", "complete"}, "complete.yaml");
  EXPECT_EQ(complete.edges.size(), 15u);
  EXPECT_EQ(classifyRigidity(makeFormation(complete)).rigidityClass, RigidityClass::GloballyRigid);
  // The hexagon's 3 nearest: both sides and, tied, both second neighbours: C6 squared, 12 edges.
  std::string comments;
  const Scenario knn = generated({"--shape", "ring", "--agents", "6", "--graph", "knn"}, "knn.yaml", &comments);
  EXPECT_EQ(knn.edges.size(), 12u);
  for (const auto& [i, j] : knn.edges) EXPECT_TRUE((j - i) % 6 == 1 || (j - i) % 6 == 2 || (j - i) % 6 == 4 || (j - i) % 6 == 5);
  EXPECT_EQ(classifyRigidity(makeFormation(knn)).rigidityClass, RigidityClass::GloballyRigid);
  EXPECT_NE(comments.find("# graph: 3 nearest neighbours (knn:3): globally rigid in 2D"), std::string::npos) << comments;
  // Every generated knn graph is globally rigid, augmented where needed: a 3D lattice and a
  // random Henneberg construction (whose minimally rigid edges are replaced).
  for (const auto& flags : std::vector<std::vector<std::string>>{
           {"--shape", "lattice", "--rows", "3", "--cols", "2", "--layers", "2", "--graph", "knn"},
           {"--shape", "henneberg", "--agents", "12", "--dimension", "2", "--seed", "4", "--graph", "knn:3"},
           {"--shape", "grid", "--rows", "3", "--cols", "4", "--graph", "knn:4"}}) {
    const Scenario s = generated(flags, "knn_more.yaml");
    EXPECT_EQ(classifyRigidity(makeFormation(s)).rigidityClass, RigidityClass::GloballyRigid) << flags[1];
  }
  const CliResult small = run(runMakeScenarioCli, {"--shape", "ring", "--agents", "6", "--graph", "knn:2"});
  EXPECT_EQ(small.status, 2);
  EXPECT_EQ(small.err, "make_scenario: error: --graph: knn:K needs K >= d + 1 = 3 (fewer cannot be globally rigid), got 2\n");
  const CliResult unknown = run(runMakeScenarioCli, {"--shape", "ring", "--agents", "6", "--graph", "star"});
  EXPECT_EQ(unknown.err, "make_scenario: error: --graph: expected complete, knn or knn:K, got 'star'\n");
}

TEST(Simulate, TheFinalLineTellsAFoldedShapeFromTheDesiredOne) {
  const std::string traj = tempPath("traj.csv"), metrics = tempPath("metrics.csv");
  const CliResult right = run(runSimulateCli, {"--scenario", kConfig + "hexagon.yaml", "--out", traj, "--metrics", metrics});
  EXPECT_EQ(right.status, 0) << right.err;
  // Step 210: the monitor's convergence step for this file (its comment).
  EXPECT_EQ(right.out, "formation: converged to the desired shape at step 210 (t = 2.940 s)\n");
  std::ifstream in(metrics);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "step,t,energy,max_distance_error,px,py,pz,ax,ay,az,cvx,cvy,cvz,wx,wy,wz,scale_error,shape_error");
  // The hexagon folded by hand (agent 1 reflected through the chord 0-2 onto the centre): an
  // equilibrium with every edge right, which the run keeps.
  std::ifstream file(kConfig + "hexagon.yaml");
  std::stringstream text;
  text << file.rdbuf();
  std::string folded = text.str();
  folded.replace(folded.find("initial_position: [1.3, 2.8481]"), 31, "initial_position: [0, 0]");
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"[3.3, 0.1]", "[3.0, 0.0]"}, {"[-1.4, 2.2981]", "[-1.4999999999999993, 2.598076211353316]"},
           {"[-3.25, -0.1]", "[-3.0, 0.0]"}, {"[-1.3, -2.3981]", "[-1.5000000000000013, -2.598076211353315]"},
           {"[1.4, -2.2981]", "[1.5000000000000004, -2.598076211353316]"}}) {
    folded.replace(folded.find(from), from.size(), to);
  }
  const std::string foldedPath = write("folded.yaml", folded);
  const CliResult other = run(runSimulateCli, {"--scenario", foldedPath, "--out", traj, "--steps", "20"});
  EXPECT_EQ(other.status, 0) << other.err;
  EXPECT_EQ(other.out, "formation: not converged: folded, at rest with every edge within tolerance but not every pair "
                       "(shape error 3 m)\n");
  // With require_convergence: true it is a failure.
  const std::string required = write("required.yaml", folded + "require_convergence: true\n");
  const CliResult fails = run(runSimulateCli, {"--scenario", required, "--out", traj, "--steps", "20"});
  EXPECT_EQ(fails.status, 1);
  EXPECT_EQ(lastLine(fails.err), "simulate: error: the formation did not converge (folded), and the scenario "
                                 "requires it (require_convergence: true)");
  // assignment: auto on the hexagon's own starts keeps the numbering (each starts nearest its slot).
  const std::string assigned = write("assigned.yaml", text.str() + "assignment: auto\n");
  const CliResult a = run(runSimulateCli, {"--scenario", assigned, "--out", traj});
  EXPECT_EQ(a.status, 0) << a.err;
  EXPECT_EQ(a.out.rfind("assignment: agent -> slot 0->0 1->1 2->2 3->3 4->4 5->5; rotation ", 0), 0u) << a.out;
  EXPECT_EQ(lastLine(a.out), "formation: converged to the desired shape at step 210 (t = 2.940 s)");
}

TEST(AssignSlots, WritesTheScenarioWithTheRobotsStartsAndTheirSlots) {
  const Scenario hexagon = loadScenario(kConfig + "hexagon.yaml");
  // Robots parked on the hexagon turned by 60 deg and shifted: robot i sits on slot i + 1.
  std::string csv = "agent,x,y,z\n";
  for (int i = 5; i >= 0; --i) {
    const Eigen::Vector2d p = hexagon.desiredPositions.col((i + 1) % 6) + Eigen::Vector2d(10.0, -2.0);
    std::ostringstream row;
    row.precision(17);
    row << i << ',' << p.x() << ',' << p.y() << ",0\n";
    csv += row.str();
  }
  const std::string starts = write("starts.csv", csv), out = tempPath("assigned_hexagon.yaml");
  const CliResult r = run(runAssignSlotsCli, {"--scenario", kConfig + "hexagon.yaml", "--starts", starts, "--out", out});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.rfind("assign_slots: agent -> slot 0->1 1->2 2->3 3->4 4->5 5->0; rotation 0.0 deg, translation (10.000, -2.000) m", 0), 0u)
      << r.err;
  const Scenario s = loadScenario(out);
  EXPECT_FALSE(s.autoAssignment);  // applied: the file launches as it is
  EXPECT_EQ(s.name, "hexagon");
  EXPECT_EQ(s.steps, hexagon.steps);
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(s.desiredPositions.col(i), hexagon.desiredPositions.col((i + 1) % 6));
    EXPECT_LT((s.initialPositions.col(i) - s.desiredPositions.col(i) - Eigen::Vector2d(10.0, -2.0)).norm(), 1e-12);
  }
  // File edge [a, b] joins slots a and b, now held by agents a - 1 and b - 1.
  ASSERT_EQ(s.edges.size(), hexagon.edges.size());
  for (std::size_t e = 0; e < s.edges.size(); ++e) {
    EXPECT_EQ((s.edges[e].first + 1) % 6, hexagon.edges[e].first);
    EXPECT_EQ((s.edges[e].second + 1) % 6, hexagon.edges[e].second);
  }
  // A bad positions file: one line, exit 2.
  const std::string bad = write("bad.csv", "agent,x,y,z\n0,1,2,0\n");
  const CliResult b = run(runAssignSlotsCli, {"--scenario", kConfig + "hexagon.yaml", "--starts", bad});
  EXPECT_EQ(b.status, 2);
  EXPECT_EQ(b.err, "assign_slots: error: " + bad + ": agent 1: no row (every agent needs one)\n");
  const std::string planar = write("planar.csv", "agent,x,y,z\n0,1,2,0.5\n");
  const CliResult p = run(runAssignSlotsCli, {"--scenario", kConfig + "hexagon.yaml", "--starts", planar});
  EXPECT_EQ(p.err, "assign_slots: error: " + planar + ": line 2: z: must be 0 in a 2D scenario, got 0.5\n");
}

// Issue 50, defect 4: a 12-agent scattered deployment (complete graph, safety filter) that ends as
// the mirror image. No line says "converged" but "not converged", with or without
// require_convergence; with `mirror: allowed` the same run converges, at the same step.
TEST(Simulate, AMirrorImageIsNotConvergedInAnyLine) {
  std::string comments;
  generated({"--shape", "ring", "--agents", "12", "--chords", "5", "--scatter", "6", "--min-gap", "0.4", "--seed", "2",
             "--safety", "0.25", "1", "0.2", "--time-step", "0.02", "--steps", "1500"},
            "mirror12.yaml", &comments);
  std::ifstream in(tempPath("mirror12.yaml"));
  std::stringstream text;
  text << in.rdbuf();
  const auto lines = [](const std::string& out) {
    std::vector<std::string> all;
    std::istringstream s(out);
    for (std::string line; std::getline(s, line);) all.push_back(line);
    return all;
  };
  for (const bool required : {false, true}) {
    const std::string path = write("mirror12_run.yaml", text.str() + (required ? "require_convergence: true\n" : ""));
    const CliResult r = run(runSimulateCli, {"--scenario", path, "--out", "/dev/null"});
    EXPECT_EQ(r.status, required ? 1 : 0) << r.err;
    const std::vector<std::string> out = lines(r.out);
    ASSERT_EQ(out.size(), 2u) << r.out;
    EXPECT_EQ(out[0].rfind("simulate: safety: closest approach 0.2", 0), 0u) << r.out;
    EXPECT_EQ(out[1], "formation: not converged: the mirror image of the desired shape from step 293 (t = 5.860 s; "
                      "mirror: forbidden)");
    for (const std::string& line : lines(r.out + r.err)) {
      const std::size_t at = line.find("converged");
      EXPECT_TRUE(at == std::string::npos || (at >= 4 && line.compare(at - 4, 4, "not ") == 0)) << line;
    }
    if (required) {
      EXPECT_EQ(r.err, "simulate: error: the formation did not converge (its mirror image), and the scenario requires "
                       "it (require_convergence: true)\n");
    }
  }
  const std::string allowed = write("mirror12_allowed.yaml", text.str() + "mirror: allowed\n");
  const CliResult a = run(runSimulateCli, {"--scenario", allowed, "--out", "/dev/null"});
  EXPECT_EQ(a.status, 0) << a.err;
  EXPECT_EQ(lastLine(a.out), "formation: converged to the desired shape at step 293 (t = 5.860 s), its mirror image "
                             "(mirror: allowed)");
}

// Issue 50, defect 5: assign_slots keeps the hexagon's 300 steps; robots parked at these starts
// are still moving at step 300 with every edge right (still settling, not folded) and converge at
// step 332 with 3000 steps; robots parked at the second set of starts fold it for good.
TEST(Simulate, AShortRunThatStillMovesIsStillSettlingNotFolded) {
  const std::string near = write("near.csv", "agent,x,y,z\n0,3.361,-0.750,0\n1,1.198,3.939,0\n2,-1.053,2.853,0\n"
                                             "3,-4.304,-1.343,0\n4,-2.366,-3.685,0\n5,2.951,-4.090,0\n");
  const std::string inside = write("inside.csv", "agent,x,y,z\n0,4.184,-0.232,0\n1,1.769,1.172,0\n2,-0.980,3.855,0\n"
                                                 "3,-2.020,1.157,0\n4,-1.019,-3.361,0\n5,2.306,-3.463,0\n");
  const auto assigned = [&](const std::string& starts, const std::string& name) {
    const std::string out = tempPath(name);
    const CliResult r = run(runAssignSlotsCli, {"--scenario", kConfig + "hexagon.yaml", "--starts", starts, "--out", out});
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(loadScenario(out).steps, 300);
    return out;
  };
  const std::string settling = assigned(near, "near.yaml");
  CliResult r = run(runSimulateCli, {"--scenario", settling, "--out", "/dev/null"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.rfind("formation: not converged: still settling at the last step (every edge within tolerance; "
                        "shape error 0.0706 m; fastest agent 0.0", 0), 0u)
      << r.out;
  r = run(runSimulateCli, {"--scenario", settling, "--out", "/dev/null", "--steps", "3000"});
  EXPECT_EQ(r.out, "formation: converged to the desired shape at step 332 (t = 4.648 s)\n");
  r = run(runSimulateCli, {"--scenario", assigned(inside, "inside.yaml"), "--out", "/dev/null", "--steps", "3000"});
  EXPECT_EQ(r.out, "formation: not converged: folded, at rest with every edge within tolerance but not every pair "
                   "(shape error 3 m)\n");
}

}  // namespace
}  // namespace vf
