#pragma once

#include <string>
#include <utility>
#include <vector>

#include "variational_formation_core/model/rigidity.hpp"

namespace vf {

/// A sensing graph chosen for its global rigidity (make_scenario --graph).
struct GloballyRigidGraph {
  std::vector<std::pair<int, int>> edges;  ///< (i, j) with i < j, sorted
  int neighbours = 0;                      ///< K of knn after augmentation (0 for complete)
  RigidityReport rigidity;                 ///< classifyRigidity of the result
  std::string description;                 ///< "complete graph" or "3 nearest neighbours (knn:3)"
};

/**
 * `--graph complete`: every pair. `--graph knn[:K]`: each agent linked to its K nearest desired
 * positions and to any as near as the K-th (ties within 1e-9 relative: the result does not
 * depend on the numbering), made symmetric; K >= d + 1, default d + 1. While the graph is not
 * globally rigid (classifyRigidity), K grows by one; K = n - 1 is the complete graph, which is
 * globally rigid, so this ends.
 * @param spec "complete", "knn" or "knn:K"; @param desired q*, d x n [m].
 * @throws InvalidInput naming --graph (unknown kind, bad K).
 */
GloballyRigidGraph globallyRigidGraph(const std::string& spec, const Positions& desired);

}  // namespace vf
