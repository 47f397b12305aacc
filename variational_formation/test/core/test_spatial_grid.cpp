// The spatial index behind sensing by distance: every query against brute force, in 2D and 3D,
// with far-out and non-finite positions; the closest pair against brute force.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/standard_normal.hpp"
#include "variational_formation_core/model/spatial_grid.hpp"
#include "test_support.hpp"

namespace vf {
namespace {

std::vector<int> bruteForce(const Positions& q, int i, double radius) {
  std::vector<int> ids;
  for (int j = 0; j < q.cols(); ++j) {
    double d2 = 0.0;
    for (int a = 0; a < q.rows(); ++a) d2 += (q(a, j) - q(a, i)) * (q(a, j) - q(a, i));
    if (j != i && d2 < radius * radius) ids.push_back(j);
  }
  return ids;
}

Positions randomPositions(std::mt19937_64& engine, int d, int n, double side) {
  Positions q(d, n);
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < d; ++a) q(a, i) = side * (uniformUnit(engine) - 0.5);
  }
  return q;
}

// within() for one agent, and neighbourLists() for all at once.
TEST(SpatialGrid, FindsExactlyTheAgentsWithinTheRadiusInAscendingId) {
  std::mt19937_64 engine(5);
  long found = 0;
  for (int d = 2; d <= 3; ++d) {
    for (int trial = 0; trial < 40; ++trial) {
      const int n = 1 + static_cast<int>(engine() % 200);
      const double cell = 0.2 + 2.0 * uniformUnit(engine);
      Positions q = randomPositions(engine, d, n, 10.0);
      if (trial % 5 == 0 && n > 3) {
        q.col(1) = q.col(0);                                         // coincident agents
        q(0, 2) = std::floor(q(0, 2) / cell) * cell;                 // on a cell boundary
      }
      SpatialGrid grid;
      grid.build(q, cell);
      for (double radius : {cell, 0.5 * cell}) {
        std::vector<int> start, all;
        grid.neighbourLists(q, radius, start, all);
        ASSERT_EQ(start.size(), static_cast<std::size_t>(n) + 1);
        for (int i = 0; i < n; ++i) {
          std::vector<int> ids{-7};  // within() appends
          grid.within(q, i, radius, ids);
          ids.erase(ids.begin());
          ASSERT_EQ(ids, bruteForce(q, i, radius)) << "d " << d << " trial " << trial << " agent " << i;
          const std::vector<int> listed(all.begin() + start[static_cast<std::size_t>(i)],
                                        all.begin() + start[static_cast<std::size_t>(i) + 1]);
          ASSERT_EQ(listed, ids) << "d " << d << " trial " << trial << " agent " << i;
          found += static_cast<long>(ids.size());
        }
      }
    }
  }
  EXPECT_GT(found, 10000);
}

TEST(SpatialGrid, StaysExactFarOutAndSkipsNonFinitePositions) {
  Positions q(2, 6);
  q << 1e12, 1e12 + 0.5, -1e15, -1e15 + 0.3, 0.0, std::nan(""),
      0.0, 0.0, 2.0, 2.1, 0.0, 0.0;
  SpatialGrid grid;
  grid.build(q, 1.0);
  for (int i = 0; i < 6; ++i) {
    std::vector<int> ids;
    grid.within(q, i, 1.0, ids);
    EXPECT_EQ(ids, bruteForce(q, i, 1.0)) << i;
  }
  std::vector<int> ids;
  grid.within(q, 0, 1.0, ids);
  EXPECT_EQ(ids, std::vector<int>{1});
  std::vector<int> start, all;
  grid.neighbourLists(q, 1.0, start, all);
  EXPECT_EQ(start, (std::vector<int>{0, 1, 2, 3, 4, 4, 4}));
  EXPECT_EQ(all, (std::vector<int>{1, 0, 3, 2}));
}

TEST(ClosestPair, AgreesWithBruteForce) {
  std::mt19937_64 engine(9);
  for (int d = 2; d <= 3; ++d) {
    for (int trial = 0; trial < 60; ++trial) {
      const int n = 2 + static_cast<int>(engine() % 150);
      // Sparse and dense configurations: the pair may lie far beyond the hint.
      const Positions q = randomPositions(engine, d, n, trial % 2 ? 100.0 : 3.0);
      double best = std::numeric_limits<double>::infinity();
      int first = -1, second = -1;
      for (int i = 0; i < n; ++i) {
        for (int j = i + 1; j < n; ++j) {
          const double distance = std::sqrt((q.col(i) - q.col(j)).squaredNorm());
          if (distance < best) {
            best = distance;
            first = i;
            second = j;
          }
        }
      }
      const ClosestPair c = closestPair(q, 0.5);
      EXPECT_EQ(c.distance, best);
      EXPECT_EQ(c.first, first);
      EXPECT_EQ(c.second, second);
    }
  }
  Positions one(2, 1);
  one << 1.0, 2.0;
  EXPECT_EQ(closestPair(one, 1.0).distance, std::numeric_limits<double>::infinity());
  EXPECT_EQ(closestPair(one, 1.0).first, -1);
  Positions bad(2, 2);
  bad << 0.0, std::nan(""), 0.0, 0.0;
  EXPECT_TRUE(std::isnan(closestPair(bad, 1.0).distance));
}

// A diverging run (issue 50): positions so far out that the bounding box's diagonal overflows to
// +inf. The grid kept doubling its cell for ever (a run with safety: hung); it must end, with the
// exact pair where a squared distance is a double and +inf (no pair) where none is.
TEST(ClosestPair, EndsFarOutWhereDistancesOverflow) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Positions apart(2, 3);  // every pair farther than 1e154 m: no squared distance is finite
  apart << -1e300, 1e300, 0.0,
           0.0, 0.0, 1e300;
  const double far = std::ldexp(1.0, 330);  // ~2e99 m, a power of two: its square and root are exact
  Positions mixed(3, 4);  // a pair `far` apart (found by doubling), two agents at +-1e300
  mixed << 1e300, 0.0, 0.0, -1e300,
           0.0, 0.0, 0.0, 5.0,
           0.0, 0.0, far, 0.0;
  for (const Positions* q : {&apart, &mixed}) {
    test::expectEndsWithin(10, [q] { closestPair(*q, 0.5); });
    if (HasFailure()) return;
  }
  const ClosestPair none = closestPair(apart, 0.5);
  EXPECT_EQ(none.distance, kInf);
  EXPECT_EQ(none.first, -1);
  const ClosestPair c = closestPair(mixed, 0.5);
  EXPECT_EQ(c.distance, far);
  EXPECT_EQ(c.first, 1);
  EXPECT_EQ(c.second, 2);
  // The grid itself far out, with cells up to +inf: exactly the pairs whose squared distance is
  // below the radius's square, as brute force finds them.
  for (double cell : {1.0, 1e154, 1e200, kInf}) {
    SpatialGrid grid;
    grid.build(mixed, cell);
    std::vector<int> start, all;
    grid.neighbourLists(mixed, cell, start, all);
    for (int i = 0; i < 4; ++i) {
      const std::vector<int> listed(all.begin() + start[static_cast<std::size_t>(i)],
                                    all.begin() + start[static_cast<std::size_t>(i) + 1]);
      EXPECT_EQ(listed, bruteForce(mixed, i, cell)) << "cell " << cell << " agent " << i;
    }
  }
  EXPECT_NE(test::thrown([&] { closestPair(mixed, 0.0); }).find("closest pair: the first cell must be > 0 m, got 0"),
            std::string::npos);
}

}  // namespace
}  // namespace vf
