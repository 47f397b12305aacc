#include "variational_formation_core/model/spatial_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"

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

namespace {

std::size_t slotOf(std::int64_t key, std::size_t mask) {
  // A multiplicative hash of the key; any spread works, the answers do not depend on it.
  return static_cast<std::size_t>((static_cast<std::uint64_t>(key) * 0x9E3779B97F4A7C15ULL) >> 20) & mask;
}

}  // namespace

const SpatialGrid::Cell* SpatialGrid::find(std::int64_t key) const {
  const std::size_t mask = cells_.size() - 1;
  std::size_t slot = slotOf(key, mask);
  while (cells_[slot].key >= 0 && cells_[slot].key != key) slot = (slot + 1) & mask;
  return cells_[slot].key < 0 ? nullptr : &cells_[slot];
}

double SpatialGrid::squaredDistance(const Positions& q, int i, int j) const {
  // (q_j - q_i)^2 = (q_i - q_j)^2 exactly: the same number whichever agent asks.
  double d2 = 0.0;
  for (int a = 0; a < dimension_; ++a) d2 += (q(a, j) - q(a, i)) * (q(a, j) - q(a, i));
  return d2;
}

void SpatialGrid::build(const Positions& q, double cellSize) {
  dimension_ = static_cast<int>(q.rows());
  cellSize_ = cellSize;
  entries_.resize(static_cast<std::size_t>(q.cols()));
  std::int64_t cell[3] = {0, 0, 0};
  nearEdge_ = false;
  for (int i = 0; i < q.cols(); ++i) {
    cellOf(q, i, cell);
    for (int a = 0; a < dimension_; ++a) nearEdge_ = nearEdge_ || cell[a] <= -kHalfRange || cell[a] >= kHalfRange - 2;
    entries_[static_cast<std::size_t>(i)] = {cellKey(cell), i};
  }
  std::sort(entries_.begin(), entries_.end());
  // Each occupied cell's run of entries, found by open addressing (keys are >= 0; -1 = empty).
  std::size_t capacity = 16;
  while (capacity < 2 * entries_.size()) capacity *= 2;
  cells_.assign(capacity, Cell{-1, 0, 0});
  const std::size_t mask = capacity - 1;
  for (std::size_t e = 0; e < entries_.size();) {
    std::size_t end = e + 1;
    while (end < entries_.size() && entries_[end].first == entries_[e].first) ++end;
    std::size_t slot = slotOf(entries_[e].first, mask);
    while (cells_[slot].key >= 0) slot = (slot + 1) & mask;
    cells_[slot] = Cell{entries_[e].first, static_cast<int>(e), static_cast<int>(end)};
    e = end;
  }
}

void SpatialGrid::within(const Positions& q, int i, double radius, std::vector<int>& out) const {
  const std::size_t first = out.size();
  std::int64_t centre[3] = {0, 0, 0}, cell[3] = {0, 0, 0};
  cellOf(q, i, centre);
  const double r2 = radius * radius;
  // The 3^d cells around i, each once: only near the clamped edge can two of them merge.
  std::int64_t keys[27];
  int count = 0;
  const int dz0 = dimension_ >= 3 ? -1 : 0, dz1 = dimension_ >= 3 ? 1 : 0;
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dz = dz0; dz <= dz1; ++dz) {
        cell[0] = centre[0] + dx;
        cell[1] = centre[1] + dy;
        cell[2] = centre[2] + dz;
        keys[count++] = cellKey(cell);
      }
    }
  }
  bool edge = false;
  for (int a = 0; a < dimension_; ++a) edge = edge || centre[a] <= -kHalfRange || centre[a] >= kHalfRange - 2;
  if (edge) {
    std::sort(keys, keys + count);
    count = static_cast<int>(std::unique(keys, keys + count) - keys);
  }
  for (int c = 0; c < count; ++c) {
    const Cell* found = find(keys[c]);
    for (int e = found ? found->begin : 0; found && e < found->end; ++e) {
      const int j = entries_[static_cast<std::size_t>(e)].second;
      if (j != i && squaredDistance(q, i, j) < r2) out.push_back(j);
    }
  }
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end());
}

void SpatialGrid::neighbourLists(const Positions& q, double radius, std::vector<int>& start,
                                 std::vector<int>& ids) const {
  const auto n = static_cast<std::size_t>(q.cols());
  start.assign(n + 1, 0);
  ids.clear();
  if (nearEdge_) {  // merged cells far out: ask agent by agent
    for (std::size_t i = 0; i < n; ++i) {
      within(q, static_cast<int>(i), radius, ids);
      start[i + 1] = static_cast<int>(ids.size());
    }
    return;
  }
  // Every pair once: each occupied cell with itself and with its neighbour cells that come
  // after it (offsets lexicographically above zero).
  const double r2 = radius * radius;
  pairs_.clear();
  const int dz = dimension_ >= 3 ? 1 : 0;
  std::int64_t cell[3] = {0, 0, 0}, other[3] = {0, 0, 0};
  for (const Cell& c : cells_) {
    if (c.key < 0) continue;
    cellOf(q, entries_[static_cast<std::size_t>(c.begin)].second, cell);
    for (int ox = 0; ox <= 1; ++ox) {
      for (int oy = ox ? -1 : 0; oy <= 1; ++oy) {
        for (int oz = (ox || oy) ? -dz : 0; oz <= dz; ++oz) {
          other[0] = cell[0] + ox;
          other[1] = cell[1] + oy;
          other[2] = cell[2] + oz;
          const bool self = ox == 0 && oy == 0 && oz == 0;
          const Cell* found = self ? &c : find(cellKey(other));
          for (int e = found ? found->begin : 0; found && e < found->end; ++e) {
            const int j = entries_[static_cast<std::size_t>(e)].second;
            for (int f = c.begin; f < (self ? e : c.end); ++f) {
              const int i = entries_[static_cast<std::size_t>(f)].second;
              if (squaredDistance(q, i, j) < r2) pairs_.emplace_back(i, j);
            }
          }
        }
      }
    }
  }
  for (const auto& [i, j] : pairs_) {
    ++start[static_cast<std::size_t>(i) + 1];
    ++start[static_cast<std::size_t>(j) + 1];
  }
  for (std::size_t i = 0; i < n; ++i) start[i + 1] += start[i];
  ids.resize(static_cast<std::size_t>(start[n]));
  std::vector<int>& fill = fill_;
  fill.assign(start.begin(), start.end() - 1);
  for (const auto& [i, j] : pairs_) {
    ids[static_cast<std::size_t>(fill[static_cast<std::size_t>(i)]++)] = j;
    ids[static_cast<std::size_t>(fill[static_cast<std::size_t>(j)]++)] = i;
  }
  for (std::size_t i = 0; i < n; ++i) std::sort(ids.begin() + start[i], ids.begin() + start[i + 1]);
}

ClosestPair closestPair(const Positions& q, double hint) {
  ClosestPair best;
  if (q.cols() < 2) return best;
  if (!q.allFinite()) {
    best.distance = std::nan("");
    return best;
  }
  if (!(hint > 0.0)) throw InvalidInput("closest pair: the first cell must be > 0 m, got " + formatNumber(hint));
  // Beyond the bounding box's diagonal every pair is within one cell of the other. Far out
  // (a diverging run) the diagonal may overflow to +inf: once cell^2 does too, every pair whose
  // squared distance is a double (< ~1.3e154 m apart) has been measured, and no other can be.
  const double diagonal = (q.rowwise().maxCoeff() - q.rowwise().minCoeff()).norm();
  SpatialGrid grid;
  for (double cell = hint;; cell *= 2.0) {
    grid.build(q, cell);
    const ClosestPair best = grid.closestWithin(q, cell);
    if (best.first >= 0 || cell > diagonal || std::isinf(cell * cell)) return best;
  }
}

ClosestPair SpatialGrid::closestWithin(const Positions& q, double radius) const {
  std::vector<int> start, ids;
  neighbourLists(q, radius, start, ids);
  return closestListed(q, radius, start, ids);
}

ClosestPair closestListed(const Positions& q, double radius, const std::vector<int>& start,
                          const std::vector<int>& ids) {
  ClosestPair best;
  double best2 = radius * radius;
  for (int i = 0; i < q.cols(); ++i) {
    for (int k = start[static_cast<std::size_t>(i)]; k < start[static_cast<std::size_t>(i) + 1]; ++k) {
      const int j = ids[static_cast<std::size_t>(k)];
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
