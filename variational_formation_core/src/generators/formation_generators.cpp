#include "variational_formation_core/generators/formation_generators.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

#include "variational_formation_core/common/invalid_input.hpp"

namespace vf {

namespace {

std::string text(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

void requireSpacing(double spacing) {
  if (!(std::isfinite(spacing) && spacing > 0.0)) {
    throw InvalidInput("--spacing: must be finite and > 0, got " + text(spacing));
  }
}

void requireAtLeast(const char* flag, int value, int minimum) {
  if (value < minimum) {
    throw InvalidInput(std::string(flag) + ": must be >= " + std::to_string(minimum) + ", got " +
                       std::to_string(value));
  }
}

/// Edges as (min, max), sorted and without duplicates or loops.
std::vector<std::pair<int, int>> normalised(const std::vector<std::pair<int, int>>& edges) {
  std::set<std::pair<int, int>> unique;
  for (const auto& [i, j] : edges) {
    if (i != j) unique.emplace(std::min(i, j), std::max(i, j));
  }
  return {unique.begin(), unique.end()};
}

/// Uniform on [0, 1) from the top 53 bits: the same numbers from every standard library,
/// unlike std::uniform_real_distribution.
double unitUniform(std::mt19937_64& engine) {
  return static_cast<double>(engine() >> 11) * 0x1.0p-53;
}

/// A uniformly random direction in R^d by rejection from the cube (no trigonometry, so no
/// libm differences between platforms).
Eigen::VectorXd randomDirection(std::mt19937_64& engine, int dimension) {
  Eigen::VectorXd v(dimension);
  for (;;) {
    for (int a = 0; a < dimension; ++a) v(a) = 2.0 * unitUniform(engine) - 1.0;
    const double norm2 = v.squaredNorm();
    if (norm2 > 1e-4 && norm2 <= 1.0) return v / std::sqrt(norm2);
  }
}

}  // namespace

FormationGraph triangulatedGrid(int rows, int cols, double spacing) {
  requireAtLeast("--rows", rows, 2);
  requireAtLeast("--cols", cols, 2);
  requireSpacing(spacing);
  FormationGraph g;
  g.dimension = 2;
  g.desiredPositions.resize(2, rows * cols);
  std::vector<std::pair<int, int>> edges;
  const auto id = [cols](int r, int c) { return r * cols + c; };
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      g.desiredPositions.col(id(r, c)) << c * spacing, r * spacing;
      if (c + 1 < cols) edges.emplace_back(id(r, c), id(r, c + 1));
      if (r + 1 < rows) edges.emplace_back(id(r, c), id(r + 1, c));
      if (r + 1 < rows && c + 1 < cols) edges.emplace_back(id(r, c), id(r + 1, c + 1));
    }
  }
  g.edges = normalised(edges);
  return g;
}

FormationGraph ringWithChords(int agents, int chords, double spacing) {
  requireAtLeast("--agents", agents, 3);
  if (chords < 0 || chords > agents - 2) {
    throw InvalidInput("--chords: must be between 0 and agents - 2 = " +
                       std::to_string(agents - 2) + ", got " + std::to_string(chords));
  }
  requireSpacing(spacing);
  FormationGraph g;
  g.dimension = 2;
  g.desiredPositions.resize(2, agents);
  const double pi = std::acos(-1.0);
  const double radius = spacing / (2.0 * std::sin(pi / agents));
  std::vector<std::pair<int, int>> edges;
  for (int i = 0; i < agents; ++i) {
    const double angle = 2.0 * pi * i / agents;
    g.desiredPositions.col(i) << radius * std::cos(angle), radius * std::sin(angle);
    for (int k = 1; k <= chords + 1; ++k) edges.emplace_back(i, (i + k) % agents);
  }
  g.edges = normalised(edges);
  return g;
}

FormationGraph bracedLattice(int rows, int cols, int layers, double spacing) {
  requireAtLeast("--rows", rows, 2);
  requireAtLeast("--cols", cols, 2);
  requireAtLeast("--layers", layers, 2);
  requireSpacing(spacing);
  FormationGraph g;
  g.dimension = 3;
  g.desiredPositions.resize(3, rows * cols * layers);
  std::vector<std::pair<int, int>> edges;
  const auto id = [rows, cols](int r, int c, int l) { return (l * rows + r) * cols + c; };
  for (int l = 0; l < layers; ++l) {
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        g.desiredPositions.col(id(r, c, l)) << c * spacing, r * spacing, l * spacing;
        const bool x = c + 1 < cols, y = r + 1 < rows, z = l + 1 < layers;
        if (x) edges.emplace_back(id(r, c, l), id(r, c + 1, l));
        if (y) edges.emplace_back(id(r, c, l), id(r + 1, c, l));
        if (z) edges.emplace_back(id(r, c, l), id(r, c, l + 1));
        // One diagonal per face, each face reached from its lowest corner exactly once.
        if (x && y) edges.emplace_back(id(r, c, l), id(r + 1, c + 1, l));
        if (x && z) edges.emplace_back(id(r, c, l), id(r, c + 1, l + 1));
        if (y && z) edges.emplace_back(id(r, c, l), id(r + 1, c, l + 1));
      }
    }
  }
  g.edges = normalised(edges);
  return g;
}

FormationGraph hennebergConstruction(int agents, int dimension, std::uint64_t seed,
                                     double spacing) {
  if (dimension != 2 && dimension != 3) {
    throw InvalidInput("--dimension: must be 2 or 3, got " + std::to_string(dimension));
  }
  requireAtLeast("--agents", agents, dimension + 1);
  requireSpacing(spacing);
  FormationGraph g;
  g.dimension = dimension;
  g.desiredPositions.setZero(dimension, agents);
  std::vector<std::pair<int, int>> edges;
  // Regular simplex of side s: (0,0[,0]), (s,0[,0]), (s/2, s sqrt(3)/2[,0]) and in 3D the apex
  // (s/2, s sqrt(3)/6, s sqrt(2/3)).
  g.desiredPositions(0, 1) = spacing;
  g.desiredPositions(0, 2) = spacing / 2.0;
  g.desiredPositions(1, 2) = spacing * std::sqrt(3.0) / 2.0;
  if (dimension == 3) {
    g.desiredPositions.col(3) << spacing / 2.0, spacing * std::sqrt(3.0) / 6.0,
        spacing * std::sqrt(2.0 / 3.0);
  }
  for (int i = 0; i <= dimension; ++i) {
    for (int j = i + 1; j <= dimension; ++j) edges.emplace_back(i, j);
  }
  std::mt19937_64 engine(seed);
  const double minDistance2 = spacing * spacing;
  for (int n = dimension + 1; n < agents; ++n) {
    Eigen::VectorXd candidate(dimension);
    bool placed = false;
    // Anchors inside the cloud are often crowded; ones on its rim always have room.
    for (int attempt = 0; attempt < 100000 && !placed; ++attempt) {
      const int anchor = static_cast<int>(unitUniform(engine) * n);
      candidate = g.desiredPositions.col(anchor) +
                  spacing * (1.0 + unitUniform(engine)) * randomDirection(engine, dimension);
      placed = true;
      for (int j = 0; j < n && placed; ++j) {
        placed = (g.desiredPositions.col(j) - candidate).squaredNorm() >= minDistance2;
      }
    }
    if (!placed) throw std::runtime_error("henneberg: no room found for agent " + std::to_string(n));
    g.desiredPositions.col(n) = candidate;
    std::vector<int> earlier(static_cast<std::size_t>(n));
    std::iota(earlier.begin(), earlier.end(), 0);
    std::stable_sort(earlier.begin(), earlier.end(), [&](int a, int b) {
      return (g.desiredPositions.col(a) - candidate).squaredNorm() <
             (g.desiredPositions.col(b) - candidate).squaredNorm();
    });
    // Henneberg type I: a new vertex joined to d earlier ones keeps minimal rigidity.
    for (int k = 0; k < dimension; ++k) edges.emplace_back(earlier[static_cast<std::size_t>(k)], n);
  }
  g.edges = normalised(edges);
  return g;
}

Positions perturbedPositions(const Positions& desired, double sigma, std::uint64_t seed) {
  if (!(std::isfinite(sigma) && sigma >= 0.0)) {
    throw InvalidInput("--perturb: must be finite and >= 0, got " + text(sigma));
  }
  std::mt19937_64 engine(seed);
  Positions q = desired;
  for (Eigen::Index i = 0; i < q.cols(); ++i) {
    for (Eigen::Index a = 0; a < q.rows(); ++a) q(a, i) += sigma * (2.0 * unitUniform(engine) - 1.0);
  }
  return q;
}

}  // namespace vf
