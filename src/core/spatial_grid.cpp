#include "variational_formation/core/spatial_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vf {

namespace {

// Cell coordinates are clamped to 21 bits each, so that three fit one key. Clamping merges
// far cells but keeps neighbouring cells neighbours: queries stay exact, only slower out there.
constexpr std::int64_t kHalfRange = std::int64_t{1} << 20;

std::int64_t clampCell(double x) {
  if (!(x >= -static_cast<double>(kHalfRange))) return x != x ? 0 : -kHalfRange;  // NaN: cell 0
  if (!(x < static_cast<double>(kHalfRange - 1))) return kHalfRange - 1;
  return static_cast<std::int64_t>(std::floor(x));
}

}  // namespace

std::int64_t SpatialGrid::cellKey(const std::int64_t* cell) const {
  std::int64_t key = 0;
  for (int a = 0; a < 3; ++a) {
    const std::int64_t c = a < dimension_ ? cell[a] : 0;
    key = (key << 21) | (std::min(std::max(c, -kHalfRange), kHalfRange - 1) + kHalfRange);
  }
  return key;
}

void SpatialGrid::cellOf(const Positions& q, int i, std::int64_t* cell) const {
  for (int a = 0; a < dimension_; ++a) cell[a] = clampCell(q(a, i) / cellSize_);
}

void SpatialGrid::build(const Positions& q, double cellSize) {
  dimension_ = static_cast<int>(q.rows());
  cellSize_ = cellSize;
  entries_.resize(static_cast<std::size_t>(q.cols()));
  std::int64_t cell[3];
  for (int i = 0; i < q.cols(); ++i) {
    cellOf(q, i, cell);
    entries_[static_cast<std::size_t>(i)] = {cellKey(cell), i};
  }
  std::sort(entries_.begin(), entries_.end());
}

void SpatialGrid::within(const Positions& q, int i, double radius, std::vector<int>& out) const {
  const std::size_t first = out.size();
  std::int64_t centre[3], cell[3] = {0, 0, 0};
  cellOf(q, i, centre);
  const double r2 = radius * radius;
  // The 3^d cells around i, each once (clamping can merge some far out).
  std::int64_t keys[27];
  int count = 0;
  const int dz0 = dimension_ >= 3 ? -1 : 0, dz1 = dimension_ >= 3 ? 1 : 0;
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dz = dz0; dz <= dz1; ++dz) {
        cell[0] = centre[0] + dx;
        cell[1] = centre[1] + dy;
        cell[2] = dimension_ >= 3 ? centre[2] + dz : 0;
        keys[count++] = cellKey(cell);
      }
    }
  }
  std::sort(keys, keys + count);
  const int distinct = static_cast<int>(std::unique(keys, keys + count) - keys);
  for (int c = 0; c < distinct; ++c) {
    auto it = std::lower_bound(entries_.begin(), entries_.end(), std::make_pair(keys[c], -1));
    for (; it != entries_.end() && it->first == keys[c]; ++it) {
      const int j = it->second;
      if (j == i) continue;
      double d2 = 0.0;
      for (int a = 0; a < dimension_; ++a) d2 += (q(a, j) - q(a, i)) * (q(a, j) - q(a, i));
      if (d2 < r2) out.push_back(j);
    }
  }
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end());
}

ClosestPair closestPair(const Positions& q, double hint) {
  ClosestPair best;
  if (q.cols() < 2) return best;
  if (!q.allFinite()) {
    best.distance = std::nan("");
    return best;
  }
  // Beyond the bounding box's diagonal every pair is within one cell of the other.
  const double diagonal = (q.rowwise().maxCoeff() - q.rowwise().minCoeff()).norm();
  SpatialGrid grid;
  for (double cell = hint;; cell *= 2.0) {
    grid.build(q, cell);
    const ClosestPair best = grid.closestWithin(q, cell);
    if (best.first >= 0 || cell > diagonal) return best;
  }
}

ClosestPair SpatialGrid::closestWithin(const Positions& q, double radius) const {
  ClosestPair best;
  double best2 = radius * radius;
  std::vector<int> near;
  for (int i = 0; i < q.cols(); ++i) {
    near.clear();
    within(q, i, radius, near);
    for (int j : near) {
      const double d2 = (q.col(i) - q.col(j)).squaredNorm();
      if (j > i && d2 < best2) {
        best2 = d2;
        best.first = i;
        best.second = j;
      }
    }
  }
  best.distance = best.first >= 0 ? std::sqrt(best2) : std::numeric_limits<double>::infinity();
  return best;
}

}  // namespace vf
