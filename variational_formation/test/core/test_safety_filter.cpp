// The safety filter (doc/maths.md §10): the projection against its KKT conditions on random
// constraint sets, the discrete guarantee over random steps, and no change at all while nothing
// binds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "variational_formation_core/common/standard_normal.hpp"
#include "variational_formation_core/safety/safety_filter.hpp"

namespace vf {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double uniform(std::mt19937_64& engine, double lo, double hi) { return lo + (hi - lo) * uniformUnit(engine); }

double dot(int d, const double* a, const double* b) {
  double s = 0.0;
  for (int k = 0; k < d; ++k) s += a[k] * b[k];
  return s;
}

/// A random half-space on the origin's side: |a| in [0.2, 3], b in [-0.05, 0] (b = 0 exactly one
/// time in eight: a pair at distance exactly r).
HalfSpace randomHalfSpace(std::mt19937_64& engine, int d, int source) {
  HalfSpace c;
  StandardNormal normal;
  double norm = 0.0;
  for (int a = 0; a < d; ++a) {
    c.normal[a] = normal(engine);
    norm += c.normal[a] * c.normal[a];
  }
  const double length = uniform(engine, 0.2, 3.0) / std::sqrt(norm);
  for (int a = 0; a < d; ++a) c.normal[a] *= length;
  c.bound = engine() % 8 == 0 ? 0.0 : -uniform(engine, 0.0, 0.05);
  c.source = source;
  return c;
}

// The projection's KKT certificate, checked from its definition (Projection's doc): primal
// feasibility within 1e-12, λ, μ >= 0, complementary slackness and stationarity
// δ - δ0 = Σ λ a - μ δ. A point with such a certificate is the projection (the problem is
// strictly convex), so this checks optimality, not only consistency.
void expectKkt(int d, const double* delta0, const std::vector<HalfSpace>& cs, double rho, const Projection& p,
               const std::string& where) {
  ASSERT_EQ(p.multipliers.size(), cs.size()) << where;
  ASSERT_TRUE(p.feasible) << where;
  double residual[3];
  for (int a = 0; a < d; ++a) residual[a] = p.delta[a] - delta0[a] + p.speedMultiplier * p.delta[a];
  const double scale = std::sqrt(dot(d, delta0, delta0));
  for (std::size_t m = 0; m < cs.size(); ++m) {
    const HalfSpace& c = cs[m];
    const double slack = dot(d, c.normal, p.delta) - c.bound;
    EXPECT_GE(slack, -1e-12) << where << " half-space " << m;
    EXPECT_GE(p.multipliers[m], -1e-10) << where << " half-space " << m;
    EXPECT_LE(std::abs(p.multipliers[m] * slack), 1e-10) << where << " half-space " << m;
    for (int a = 0; a < d; ++a) residual[a] -= p.multipliers[m] * c.normal[a];
  }
  const double norm = std::sqrt(dot(d, p.delta, p.delta));
  EXPECT_LE(norm, rho + 1e-12) << where;
  EXPECT_GE(p.speedMultiplier, -1e-10) << where;
  if (std::isfinite(rho)) {
    EXPECT_LE(std::abs(p.speedMultiplier * (norm - rho)), 1e-10) << where;
  } else {
    EXPECT_EQ(p.speedMultiplier, 0.0) << where;
  }
  EXPECT_LE(std::sqrt(dot(d, residual, residual)), 1e-10 * (1.0 + scale)) << where;
}

TEST(SafetyProjection, SatisfiesKktOnThousandsOfRandomConstraintSets) {
  std::mt19937_64 engine(31);
  StandardNormal normal;
  int binding = 0, ballBinding = 0, several = 0;
  for (int d = 2; d <= 3; ++d) {
    for (int trial = 0; trial < 3000; ++trial) {
      const int count = static_cast<int>(engine() % 9);
      std::vector<HalfSpace> cs;
      for (int m = 0; m < count; ++m) cs.push_back(randomHalfSpace(engine, d, m));
      double delta0[3] = {0.0, 0.0, 0.0};
      const double size = uniform(engine, 0.0, 0.08);
      for (int a = 0; a < d; ++a) delta0[a] = size * normal(engine);
      const double rho = engine() % 2 ? kInf : uniform(engine, 0.002, 0.06);
      const Projection p = projectDisplacement(d, delta0, cs, rho);
      expectKkt(d, delta0, cs, rho, p, "d " + std::to_string(d) + " trial " + std::to_string(trial));
      binding += p.changed;
      ballBinding += p.speedLimited;
      several += p.active.size() >= 2;
      for (int m : p.active) EXPECT_GE(p.multipliers[static_cast<std::size_t>(m)], 0.0);
    }
  }
  // The sets exercise every kind of face: one, two or three binding half-spaces, and the ball.
  EXPECT_GT(binding, 2000);
  EXPECT_GT(ballBinding, 500);
  EXPECT_GT(several, 300);
}

TEST(SafetyProjection, ReturnsDeltaZeroItselfBitForBitWhenNothingBinds) {
  std::mt19937_64 engine(7);
  StandardNormal normal;
  int tight = 0;
  for (int d = 2; d <= 3; ++d) {
    for (int trial = 0; trial < 2000; ++trial) {
      std::vector<HalfSpace> cs;
      for (int m = 0; m < 6; ++m) cs.push_back(randomHalfSpace(engine, d, m));
      double delta0[3] = {0.0, 0.0, 0.0};
      for (int a = 0; a < d; ++a) delta0[a] = 0.1 * normal(engine);
      // Move every half-space δ0 violates onto δ0 (b = a·δ0 < 0): δ0 is feasible, some tightly.
      for (HalfSpace& c : cs) {
        const double lhs = dot(d, c.normal, delta0);
        tight += lhs < c.bound;
        c.bound = std::min(c.bound, lhs);
      }
      const double rho = engine() % 2 ? kInf : std::sqrt(dot(d, delta0, delta0));  // |δ0| = ρ still inside
      const Projection p = projectDisplacement(d, delta0, cs, rho);
      EXPECT_FALSE(p.changed) << trial;
      EXPECT_EQ(std::memcmp(p.delta, delta0, sizeof(double) * static_cast<std::size_t>(d)), 0) << trial;
      EXPECT_TRUE(p.active.empty());
    }
  }
  EXPECT_GT(tight, 1000);
}

TEST(SafetyProjection, KnownCases) {
  // One half-space x >= -0.01 and δ0 = (-0.05, 0.02): the projection is (-0.01, 0.02), λ = 0.04.
  std::vector<HalfSpace> cs(1);
  cs[0].normal[0] = 1.0;
  cs[0].bound = -0.01;
  const double delta0[2] = {-0.05, 0.02};
  Projection p = projectDisplacement(2, delta0, cs, kInf);
  EXPECT_NEAR(p.delta[0], -0.01, 1e-15);
  EXPECT_NEAR(p.delta[1], 0.02, 1e-15);
  EXPECT_NEAR(p.multipliers[0], 0.04, 1e-15);
  EXPECT_EQ(p.active, std::vector<int>{0});
  // Only the ball: δ0 scaled to ρ.
  p = projectDisplacement(2, delta0, {}, 0.01);
  EXPECT_NEAR(std::hypot(p.delta[0], p.delta[1]), 0.01, 1e-15);
  EXPECT_NEAR(p.delta[0] / p.delta[1], -2.5, 1e-12);
  EXPECT_TRUE(p.speedLimited);
  // Two walls through 0 that δ0 violates both: δ = 0 is the nearest point.
  cs.resize(2);
  cs[0].bound = 0.0;
  cs[1].normal[0] = 0.0;
  cs[1].normal[1] = -1.0;
  cs[1].bound = 0.0;
  const double up[2] = {-1.0, 1.0};
  p = projectDisplacement(2, up, cs, kInf);
  EXPECT_NEAR(p.delta[0], 0.0, 1e-15);
  EXPECT_NEAR(p.delta[1], 0.0, 1e-15);
  EXPECT_EQ(p.active, (std::vector<int>{0, 1}));
}

TEST(SafetyConstraints, PairsWithinTheSensingRadiusInIdOrderThenObstacles) {
  SafetySettings s;
  s.radius = 0.2;
  s.sensingRadius = 1.0;
  s.gamma = 0.5;
  const double q[2] = {0.0, 0.0};
  std::vector<SensedAgent> sensed(3);
  sensed[0].id = 1;
  sensed[0].position[0] = 0.5;  // z = (-0.5, 0)
  sensed[1].id = 4;
  sensed[1].position[0] = 2.0;  // beyond R: skipped
  sensed[2].id = 7;
  sensed[2].position[1] = -0.3;  // z = (0, 0.3)
  std::vector<Obstacle> obstacles(2);
  obstacles[0].centre << 0.0, 0.8, 0.0;  // disc of radius 0.3: nearest point (0, 0.5), w = (0, -0.5)
  obstacles[0].radius = 0.3;
  obstacles[1].shape = Obstacle::Shape::Box;  // box [0.4, 1] x [-1, 1]: w = (-0.4, 0)
  obstacles[1].min << 0.4, -1.0, 0.0;
  obstacles[1].max << 1.0, 1.0, 0.0;
  std::vector<HalfSpace> cs;
  safetyConstraints(s, 2, q, sensed, obstacles, cs);
  ASSERT_EQ(cs.size(), 4u);
  EXPECT_EQ(cs[0].source, 1);
  EXPECT_EQ(cs[0].normal[0], -1.0);
  EXPECT_DOUBLE_EQ(cs[0].bound, -0.25 * (0.25 - 0.04));
  EXPECT_EQ(cs[1].source, 7);
  EXPECT_DOUBLE_EQ(cs[1].normal[1], 0.6);
  EXPECT_EQ(cs[2].source, -1);
  EXPECT_DOUBLE_EQ(cs[2].normal[1], -1.0);
  EXPECT_DOUBLE_EQ(cs[2].bound, -0.5 * (0.25 - 0.01));
  EXPECT_EQ(cs[3].source, -2);
  EXPECT_DOUBLE_EQ(cs[3].normal[0], -0.8);
  EXPECT_DOUBLE_EQ(cs[3].bound, -0.5 * (0.16 - 0.01));
  // A pair already closer than r (rounding) may not come closer: b = 0, never > 0.
  sensed[0].position[0] = 0.19;
  safetyConstraints(s, 2, q, sensed, obstacles, cs);
  EXPECT_EQ(cs[0].bound, 0.0);
  std::swap(sensed[0], sensed[2]);
  EXPECT_THROW(safetyConstraints(s, 2, q, sensed, obstacles, cs), std::invalid_argument);
}

/// Agents at least `gap` apart, uniform in a box of side `side`.
std::vector<Eigen::Vector3d> scatter(std::mt19937_64& engine, int d, int n, double side, double gap) {
  std::vector<Eigen::Vector3d> q;
  while (static_cast<int>(q.size()) < n) {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int a = 0; a < d; ++a) x(a) = uniform(engine, 0.0, side);
    bool apart = true;
    for (const auto& y : q) apart = apart && (x - y).norm() >= gap;
    if (apart) q.push_back(x);
  }
  return q;
}

// doc/maths.md §10: when every agent filters its own δ0 with the others' step-(k+1) positions,
// b(z^{k+2}) >= (1 - γ) b(z^{k+1}) for every sensed pair, and the same with (r/2)^2 for obstacles:
// no pair ever gets closer than r, no agent closer than r/2 to an obstacle. Steps are drawn at
// random, large and aimed at each other, so that the filter binds often.
TEST(SafetyFilter, KeepsTheDiscreteBarrierOverRandomSteps) {
  std::mt19937_64 engine(2017);
  StandardNormal normal;
  long pairChecks = 0, obstacleChecks = 0, binds = 0;
  for (int d = 2; d <= 3; ++d) {
    for (int trial = 0; trial < 60; ++trial) {
      SafetySettings s;
      s.radius = uniform(engine, 0.1, 0.4);
      s.sensingRadius = s.radius + uniform(engine, 0.3, 1.0);
      s.gamma = engine() % 4 == 0 ? 1.0 : uniform(engine, 0.05, 1.0);
      s.maxSpeed = engine() % 2 ? kInf : uniform(engine, 1.0, 10.0);
      const double h = 0.02;
      const int n = 3 + static_cast<int>(engine() % 6);
      std::vector<Obstacle> obstacles(2);
      obstacles[0].centre(0) = -0.6;
      obstacles[0].radius = 0.3;
      obstacles[1].shape = Obstacle::Shape::Box;
      obstacles[1].min << 2.2, 0.0, 0.0;
      obstacles[1].max << 2.6, 1.5, 1.5;
      std::vector<Eigen::Vector3d> q = scatter(engine, d, n, 1.5, s.radius * 1.01);
      for (int step = 0; step < 40; ++step) {
        std::vector<Eigen::Vector3d> next(q);
        for (int i = 0; i < n; ++i) {
          const auto self = static_cast<std::size_t>(i);
          std::vector<SensedAgent> sensed;
          for (int j = 0; j < n; ++j) {
            if (j == i) continue;
            SensedAgent a;
            a.id = j;
            for (int c = 0; c < 3; ++c) a.position[c] = q[static_cast<std::size_t>(j)](c);
            sensed.push_back(a);
          }
          // Toward another agent, plus noise (the filter has to do all the work).
          const auto target = static_cast<std::size_t>(engine() % static_cast<unsigned>(n));
          Eigen::Vector3d delta0 = Eigen::Vector3d::Zero();
          for (int a = 0; a < d; ++a) delta0(a) = 0.1 * normal(engine);
          delta0 += 0.8 * (q[target] - q[self]);
          // Pairs beyond R state nothing: a step may not cross R - r with the other's (maths.md §10).
          const double longest = 0.49 * (s.sensingRadius - s.radius);
          if (delta0.norm() > longest) delta0 *= longest / delta0.norm();
          const SafeStep f = filterDisplacement(s, h, d, q[self].data(), delta0.data(), sensed, obstacles);
          ASSERT_TRUE(f.projection.feasible);
          binds += f.projection.changed;
          for (int a = 0; a < d; ++a) next[self](a) += f.projection.delta[a];
        }
        const double r2 = s.radius * s.radius;
        for (std::size_t i = 0; i < q.size(); ++i) {
          for (std::size_t j = i + 1; j < q.size(); ++j) {
            const double before = (q[i] - q[j]).squaredNorm();
            if (!(before < s.sensingRadius * s.sensingRadius)) continue;
            const double after = (next[i] - next[j]).squaredNorm();
            EXPECT_GE(after - r2, (1.0 - s.gamma) * (before - r2) - 1e-12) << "d " << d << " trial " << trial;
            ++pairChecks;
          }
          for (const Obstacle& o : obstacles) {
            double w0[3], w1[3];
            obstacleOffset(o, d, q[i].data(), w0);
            obstacleOffset(o, d, next[i].data(), w1);
            const double before = dot(d, w0, w0), after = dot(d, w1, w1);
            if (!(before < s.sensingRadius * s.sensingRadius)) continue;
            EXPECT_GE(after - 0.25 * r2, (1.0 - s.gamma) * (before - 0.25 * r2) - 1e-12) << "d " << d;
            ++obstacleChecks;
          }
        }
        q = next;
      }
    }
  }
  EXPECT_GT(pairChecks, 10000);
  EXPECT_GT(obstacleChecks, 1000);
  EXPECT_GT(binds, 5000);
}

/// The settings of the README's deployments: r = 0.25 m, R = 1 m, γ = 0.2, no speed limit.
SafetySettings deploymentSettings() {
  SafetySettings s;
  s.radius = 0.25;
  s.sensingRadius = 1.0;
  s.gamma = 0.2;
  return s;
}

TEST(SafetyFilter, LeavesTheNextPositionUntouchedWhileNothingBinds) {
  SafetySettings s = deploymentSettings();
  const double q[2] = {0.1, 0.7};
  double next[2] = {0.1 + 1.0 / 3.0, 0.7 - 1e-3};
  const double before[2] = {next[0], next[1]};
  std::vector<SensedAgent> sensed(1);
  sensed[0].id = 3;
  sensed[0].position[0] = -0.5;  // behind: moving away never binds
  sensed[0].position[1] = 0.7;
  const SafeStep f = filterNextPosition(s, 0.02, 2, q, next, sensed, {});
  EXPECT_FALSE(f.projection.changed);
  EXPECT_EQ(std::memcmp(next, before, sizeof next), 0);
  ASSERT_EQ(f.constraints.size(), 1u);
  // Toward it, fast: it binds, and the position moves.
  next[0] = -0.4;
  const SafeStep g = filterNextPosition(s, 0.02, 2, q, next, sensed, {});
  EXPECT_TRUE(g.projection.changed);
  EXPECT_GT(next[0], -0.4);
  EXPECT_EQ(g.projection.active, std::vector<int>{0});
}

// A diverging run (issue 50): an update that is no longer finite must reach the run as it is,
// with or without a speed limit and with a neighbour in reach, not be held at q (δ = 0), which
// hid the divergence and left the run going.
TEST(SafetyFilter, PassesANonFiniteStepOnUntouched) {
  SafetySettings s = deploymentSettings();
  const double q[2] = {0.1, 0.7};
  std::vector<SensedAgent> sensed(1);
  sensed[0].id = 3;
  sensed[0].position[0] = 0.4;  // 0.3 m ahead: in reach, and a step toward it binds
  sensed[0].position[1] = 0.7;
  const double nan = std::nan("");
  for (double maxSpeed : {kInf, 2.0}) {
    s.maxSpeed = maxSpeed;
    for (const auto& bad : {std::vector<double>{nan, 0.7}, {kInf, 0.7}, {-kInf, kInf}, {0.4, nan}}) {
      double next[2] = {bad[0], bad[1]};
      const SafeStep f = filterNextPosition(s, 0.02, 2, q, next, sensed, {});
      const std::string where = "max speed " + std::to_string(maxSpeed) + ", next (" + std::to_string(bad[0]) +
                                ", " + std::to_string(bad[1]) + ")";
      EXPECT_FALSE(f.projection.changed) << where;
      EXPECT_TRUE(f.projection.active.empty()) << where;
      EXPECT_EQ(std::memcmp(next, bad.data(), sizeof next), 0) << where << ": became (" << next[0] << ", " << next[1] << ")";
    }
  }
}

}  // namespace
}  // namespace vf
