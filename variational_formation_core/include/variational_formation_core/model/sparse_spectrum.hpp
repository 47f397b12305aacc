#pragma once

#include <Eigen/SparseCore>

#include "variational_formation_core/model/formation.hpp"

namespace vf {

/// Above this many unknowns (n d), the checks at load use the sparse matrices below instead of
/// dense O((n d)^3) factorisations; at or below it they are exactly what they were.
constexpr int kDenseSpectrumLimit = 400;

/// The Hessian of V at q (the entries of Formation::hessian), sparse: 4 d x d blocks per edge.
Eigen::SparseMatrix<double> sparseHessian(const Formation& formation, const Positions& q);

/// The rigidity matrix at q (the entries of Formation::rigidityMatrix), sparse: 2 d per row.
Eigen::SparseMatrix<double> sparseRigidityMatrix(const Formation& formation, const Positions& q);

/**
 * Largest eigenvalue of a symmetric matrix, by Lanczos (the three-term recurrence, O(n) work
 * per step) from a fixed start vector (deterministic). Stops when the top Ritz value has moved by
 * less than 1e-14 of itself at two checks in a row (every 8 steps), or after min(n, 600) steps.
 */
double largestEigenvalue(const Eigen::SparseMatrix<double>& a);

/// Numerical rank of a sparse matrix by a sparse QR, its columns in their own order (a
/// formation's numbering along its shape keeps R banded): diagonal entries of R
/// above relativeTolerance x max(1, largest column norm) count.
int sparseRank(const Eigen::SparseMatrix<double>& a, double relativeTolerance);

}  // namespace vf
