#pragma once

#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "variational_formation_core/common/types.hpp"

namespace vf {

/// The closest pair of a configuration.
struct ClosestPair {
  /// [m]; +inf with fewer than two agents or none closer than ~1.3e154 m (whose squared distance
  /// overflows a double: a diverging run), NaN if a position is not finite
  double distance = std::numeric_limits<double>::infinity();
  int first = -1;   ///< the pair's ids, first < second (-1 if none)
  int second = -1;
};

/**
 * A uniform grid over the agents' positions, built once per step: "who is within R of agent i"
 * for R up to the cell size, in ascending id, at O(n) per step for bounded density (each query
 * reads the 3^d cells around i). Agents are kept sorted by (cell, id) and each occupied cell found
 * by hashing; answers are sorted, so nothing depends on the hash or on the order of insertion.
 */
class SpatialGrid {
 public:
  /// Indexes the columns of q (d x n, d = 2 or 3) in cells of side `cellSize` [m] > 0.
  void build(const Positions& q, double cellSize);
  /**
   * Appends to `out` every j != i with |q_j - q_i|^2 < radius^2, in ascending j.
   * @param q the positions build() indexed. @param radius [m], at most the cell size.
   */
  void within(const Positions& q, int i, double radius, std::vector<int>& out) const;
  /**
   * Every agent's within() at once, at about half the cost (each pair is measured once): the
   * ids near agent i are ids[start[i] .. start[i + 1]), ascending, exactly as within() gives them.
   */
  void neighbourLists(const Positions& q, double radius, std::vector<int>& start, std::vector<int>& ids) const;
  /// The closest pair nearer than `radius` (<= the cell size) [m]; first = -1 if none is.
  ClosestPair closestWithin(const Positions& q, double radius) const;
  double cellSize() const { return cellSize_; }

 private:
  struct Cell {
    std::int64_t key;  // -1: an empty slot
    int begin, end;    // its run in entries_
  };
  std::int64_t cellKey(const std::int64_t* cell) const;
  const Cell* find(std::int64_t key) const;
  double squaredDistance(const Positions& q, int i, int j) const;
  void cellOf(const Positions& q, int i, std::int64_t* cell) const;

  int dimension_ = 0;
  double cellSize_ = 0.0;
  std::vector<std::pair<std::int64_t, int>> entries_;  // (cell key, id), sorted
  std::vector<Cell> cells_;  // the occupied cells, by hash of their key
  bool nearEdge_ = false;    // some agent's cell is where clamping merges cells
  mutable std::vector<std::pair<int, int>> pairs_;  // neighbourLists' scratch
  mutable std::vector<int> fill_;
};

/// The closest pair nearer than `radius` [m] among neighbour lists as SpatialGrid::neighbourLists
/// gives them (first = -1 if none).
ClosestPair closestListed(const Positions& q, double radius, const std::vector<int>& start,
                          const std::vector<int>& ids);

/**
 * The closest pair of q at O(n) for bounded density: a SpatialGrid of cell `hint` [m] > 0
 * (e.g. the sensing radius), doubled until some pair lies within it. Ties go to the smallest
 * (first, second). Ends for any finite q, however far out (ClosestPair::distance).
 * @throws InvalidInput if hint is not > 0.
 */
ClosestPair closestPair(const Positions& q, double hint);

}  // namespace vf
