#pragma once

#include <vector>

#include <Eigen/Dense>

namespace vf {

/**
 * The assignment of minimum total cost (Hungarian method, Kuhn-Munkres, with row and column
 * potentials and one shortest augmenting path per row: O(n^3)). Deterministic: among equal
 * choices it takes the lowest column index.
 * @param cost n x n, finite.
 * @return column[i], the column assigned to row i (a permutation of 0..n-1).
 * @throws InvalidInput if the matrix is not square or has a non-finite entry.
 */
std::vector<int> minimumCostAssignment(const Eigen::MatrixXd& cost);

}  // namespace vf
