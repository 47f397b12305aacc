// Slot assignment: the Hungarian method against brute force, Procrustes on known motions, and
// assignSlots recovering a known permutation and rigid motion; the scenario field `assignment`.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "test_support.hpp"
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/hungarian.hpp"
#include "variational_formation_core/model/slot_assignment.hpp"

namespace vf {
namespace {

double totalCost(const Eigen::MatrixXd& cost, const std::vector<int>& column) {
  double sum = 0.0;
  for (std::size_t i = 0; i < column.size(); ++i) sum += cost(static_cast<Eigen::Index>(i), column[i]);
  return sum;
}

TEST(Hungarian, MatchesBruteForceOnRandomInstances) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  for (int trial = 0; trial < 300; ++trial) {
    const int n = 1 + trial % 7;
    Eigen::MatrixXd cost(n, n);
    // Every third instance has small integer costs, so ties are common.
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) cost(i, j) = trial % 3 == 0 ? std::floor(u(rng) / 3.0) : u(rng);
    std::vector<int> p(n);
    std::iota(p.begin(), p.end(), 0);
    double best = std::numeric_limits<double>::infinity();
    do best = std::min(best, totalCost(cost, p));
    while (std::next_permutation(p.begin(), p.end()));
    const std::vector<int> got = minimumCostAssignment(cost);
    std::vector<int> sorted = got;
    std::sort(sorted.begin(), sorted.end());
    for (int i = 0; i < n; ++i) ASSERT_EQ(sorted[i], i) << "not a permutation, trial " << trial;
    EXPECT_NEAR(totalCost(cost, got), best, 1e-9) << "trial " << trial;
  }
}

TEST(Hungarian, RejectsBadMatrices) {
  EXPECT_THROW(minimumCostAssignment(Eigen::MatrixXd::Zero(2, 3)), InvalidInput);
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(2, 2);
  c(1, 0) = std::nan("");
  EXPECT_THROW(minimumCostAssignment(c), InvalidInput);
}

Eigen::MatrixXd rotation2D(double angle) {
  Eigen::MatrixXd r(2, 2);
  r << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  return r;
}

Positions randomShape(int d, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  Positions q(d, n);
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < d; ++a) q(a, i) = u(rng);
  return q;
}

TEST(Procrustes, RecoversARigidMotionAndHandlesTheMirror) {
  const Positions b = randomShape(2, 6, 3);
  const Eigen::MatrixXd r = rotation2D(2.5);
  const Eigen::Vector2d t(1.0, -3.0);
  const Positions a = (r * b).colwise() + t;
  const RigidFit fit = fitRigidMotion(a, b, false);
  EXPECT_LT((fit.rotation - r).norm(), 1e-12);
  EXPECT_LT((fit.translation - t).norm(), 1e-12);
  EXPECT_LT(fit.squaredResidual, 1e-24);
  EXPECT_FALSE(fit.reflection);
  // The mirror image: only a reflection fits it exactly.
  Positions mirrored = a;
  mirrored.row(0) *= -1.0;
  const RigidFit proper = fitRigidMotion(mirrored, b, false), any = fitRigidMotion(mirrored, b, true);
  EXPECT_NEAR(proper.rotation.determinant(), 1.0, 1e-12);
  EXPECT_GT(proper.squaredResidual, 0.1);
  EXPECT_TRUE(any.reflection);
  EXPECT_LT(any.squaredResidual, 1e-20);
  EXPECT_TRUE(isMirrorImage(mirrored, b));
  EXPECT_FALSE(isMirrorImage(a, b));
  EXPECT_TRUE(isMirrorImage(3.0 * mirrored, b));  // scale-free
  // A collinear shape is its own mirror image.
  Positions line(2, 3);
  line << 0, 1, 2, 0, 0, 0;
  Positions flipped = line;
  flipped.row(1) *= -1.0;
  EXPECT_FALSE(isMirrorImage(flipped, line));
  EXPECT_FALSE(isMirrorImage(line * -1.0, line));
}

/// starts_i = R q*_{slot(i)} + t for a known slot permutation.
Positions moved(const Positions& desired, const std::vector<int>& slot, const Eigen::MatrixXd& r,
                const Eigen::VectorXd& t) {
  Positions q(desired.rows(), desired.cols());
  for (std::size_t i = 0; i < slot.size(); ++i) q.col(static_cast<Eigen::Index>(i)) = r * desired.col(slot[i]) + t;
  return q;
}

TEST(SlotAssignment, RecoversAKnownPermutationAndRotationExactly) {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const int n = 4 + static_cast<int>(seed % 6);
    const int d = seed % 2 ? 2 : 3;
    const Positions desired = randomShape(d, n, seed);
    std::vector<int> slot(n);
    std::iota(slot.begin(), slot.end(), 0);
    std::shuffle(slot.begin(), slot.end(), std::mt19937_64(seed + 100));
    Eigen::MatrixXd r;
    if (d == 2) {
      r = rotation2D(0.37 * static_cast<double>(seed));
    } else {
      r = Eigen::AngleAxisd(0.5 * static_cast<double>(seed), Eigen::Vector3d(1.0, 2.0, -0.5).normalized()).toRotationMatrix();
    }
    const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(d, 3.0, -1.0);
    const SlotAssignment s = assignSlots(moved(desired, slot, r, t), desired, false);
    EXPECT_EQ(s.slotOfAgent, slot) << "seed " << seed;
    EXPECT_LT((s.motion.rotation - r).norm(), 1e-9) << "seed " << seed;
    EXPECT_LT((s.motion.translation - t).norm(), 1e-9) << "seed " << seed;
    EXPECT_LT(s.cost, 1e-18) << "seed " << seed;
    // The same inputs, the same answer (every agent computes this at load).
    const SlotAssignment again = assignSlots(moved(desired, slot, r, t), desired, false);
    EXPECT_EQ(again.slotOfAgent, s.slotOfAgent);
    EXPECT_EQ(again.cost, s.cost);
  }
}

TEST(SlotAssignment, AMirrorOnlyWhenAllowed) {
  const Positions desired = randomShape(2, 7, 11);
  std::vector<int> slot = {3, 0, 6, 1, 5, 2, 4};
  Eigen::MatrixXd mirror = rotation2D(1.1);
  mirror.col(1) *= -1.0;  // a reflection
  const Positions starts = moved(desired, slot, mirror, Eigen::Vector2d(0.5, 0.5));
  const SlotAssignment allowed = assignSlots(starts, desired, true);
  EXPECT_EQ(allowed.slotOfAgent, slot);
  EXPECT_TRUE(allowed.motion.reflection);
  EXPECT_LT(allowed.cost, 1e-18);
  const SlotAssignment forbidden = assignSlots(starts, desired, false);
  EXPECT_FALSE(forbidden.motion.reflection);
  EXPECT_GT(forbidden.cost, 1e-3);
  // Never worse than the numbering as given, with its own best motion.
  EXPECT_LE(forbidden.cost, forbidden.costAsGiven + 1e-12);
}

TEST(SlotAssignment, LowersTheCostOfScatteredStarts) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 4.0);
  const Positions hexagon = loadScenario(test::configPath("hexagon")).desiredPositions / 3.0;
  for (int trial = 0; trial < 20; ++trial) {
    Positions starts(2, 6);
    for (int i = 0; i < 6; ++i) starts.col(i) << u(rng), u(rng);
    const SlotAssignment s = assignSlots(starts, hexagon, false);
    EXPECT_LE(s.cost, s.costAsGiven + 1e-12);
    // A local optimum of both halves: the Hungarian method keeps the permutation for the motion.
    const Positions target = (s.motion.rotation * hexagon).colwise() + s.motion.translation;
    Eigen::MatrixXd cost(6, 6);
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) cost(i, j) = (starts.col(i) - target.col(j)).squaredNorm();
    EXPECT_NEAR(totalCost(cost, minimumCostAssignment(cost)), s.cost, 1e-9);
  }
}

const std::string kAssigned = R"(name: assigned
dimension: 2
kappa: 2
time_step: 0.01
steps: 10
assignment: auto
agents:
  - {id: 0, initial_position: [0, 1], desired_position: [0, 0]}
  - {id: 1, initial_position: [0, 0], desired_position: [2, 0]}
  - {id: 2, initial_position: [2, 0], desired_position: [2.2, 1.1]}
  - {id: 3, initial_position: [2.3, 1.1], desired_position: [0, 1]}
edges: [[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]]
)";

TEST(SlotAssignment, TheScenarioFieldPermutesSlotsAndEdgesFollowThem) {
  const Scenario plain = parseScenario(std::string(kAssigned).replace(kAssigned.find("assignment: auto"), 16, "assignment: none"), "f");
  EXPECT_TRUE(plain.assignment.slotOfAgent.empty());
  const Scenario s = parseScenario(kAssigned, "f");
  ASSERT_EQ(s.assignment.slotOfAgent.size(), 4u);
  // A quadrilateral without symmetry; agent i starts at slot i - 1 (mod 4), agent 3 0.1 m off.
  EXPECT_EQ(s.assignment.slotOfAgent, (std::vector<int>{3, 0, 1, 2}));
  for (int i = 0; i < 4; ++i) EXPECT_EQ(s.desiredPositions.col(i), plain.desiredPositions.col(s.assignment.slotOfAgent[i]));
  // Edge [a, b] of the file joins slots a and b: now the agents holding them.
  ASSERT_EQ(s.edges.size(), plain.edges.size());
  for (std::size_t e = 0; e < s.edges.size(); ++e) {
    EXPECT_EQ(s.assignment.slotOfAgent[s.edges[e].first], plain.edges[e].first);
    EXPECT_EQ(s.assignment.slotOfAgent[s.edges[e].second], plain.edges[e].second);
  }
  // So the desired distances, edge by edge, are the file's.
  const Formation a = makeFormation(s), b = makeFormation(plain);
  for (std::size_t e = 0; e < s.edges.size(); ++e) EXPECT_EQ(a.edges()[e].desiredDistance, b.edges()[e].desiredDistance);
}

TEST(SlotAssignment, BadFieldsAndTooManyAgents) {
  const auto error = [](const std::string& text) {
    try {
      parseScenario(text, "f");
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  std::string bad = kAssigned;
  bad.replace(bad.find("assignment: auto"), 16, "assignment: yes");
  EXPECT_EQ(error(bad), "f: assignment: expected auto or none, got 'yes'");
  bad = kAssigned;
  bad.replace(bad.find("assignment: auto"), 16, "mirror: sometimes");
  EXPECT_EQ(error(bad), "f: mirror: expected allowed or forbidden, got 'sometimes'");
  std::string many = "name: many\ndimension: 2\nkappa: 2\ntime_step: 0.01\nsteps: 1\nassignment: auto\nagents:\n";
  for (int i = 0; i <= kMaxAssignedAgents; ++i) {
    many += "  - {id: " + std::to_string(i) + ", initial_position: [" + std::to_string(i) + ", 0], desired_position: [0, " +
            std::to_string(i) + "]}\n";
  }
  EXPECT_NE(error(many).find("assignment: auto is for at most 200 agents"), std::string::npos) << error(many);
}

}  // namespace
}  // namespace vf
