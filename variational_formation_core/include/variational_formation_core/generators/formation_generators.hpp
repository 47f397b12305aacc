#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "variational_formation_core/common/types.hpp"

namespace vf {

/// A desired shape q* and its sensing graph, as make_scenario generates them.
struct FormationGraph {
  int dimension = 0;
  Positions desiredPositions;                ///< d x n [m]
  std::vector<std::pair<int, int>> edges;    ///< (i, j) with i < j, no duplicates
};

/**
 * Triangulated 2D grid: agent r * cols + c at (c s, r s); the edges of every cell and its
 * diagonal from (r, c) to (r + 1, c + 1). 3 rows cols - 2 rows - 2 cols + 1 edges: minimally
 * rigid iff rows == 2 or cols == 2.
 * @param spacing s [m], the side of a cell.
 * @throws InvalidInput naming --rows, --cols or --spacing (rows, cols >= 2, s > 0).
 */
FormationGraph triangulatedGrid(int rows, int cols, double spacing);

/**
 * n agents on a circle, neighbours s apart (radius s / (2 sin(pi / n))), with the ring edges
 * (i, i + 1) and the chords (i, i + k) for k = 2 .. chords + 1, indices mod n, duplicates
 * dropped. chords = 1 (every second neighbour) is infinitesimally rigid for every n >= 4.
 * @throws InvalidInput naming --agents (n >= 3), --chords (0 .. n - 2) or --spacing.
 */
FormationGraph ringWithChords(int agents, int chords, double spacing);

/**
 * 3D cubic lattice, cols x rows x layers agents s apart, agent (l * rows + r) * cols + c at
 * (c s, r s, l s). Every cell edge, and one diagonal on every face (from the corner with the
 * smallest indices), so that each cell is a triangulated convex polyhedron (rigid by
 * Cauchy-Dehn) and neighbouring cells share a rigid face. A 2 x 2 x 2 lattice is minimally
 * rigid (18 = 3 * 8 - 6 edges).
 * @throws InvalidInput naming --rows, --cols, --layers (each >= 2) or --spacing.
 */
FormationGraph bracedLattice(int rows, int cols, int layers, double spacing);

/**
 * Random Henneberg type-I construction in R^d: a regular simplex of side s (d + 1 agents,
 * every pair joined), then each new agent is placed at distance [s, 2 s) from a random earlier
 * one, at least s from all of them, and joined to its d nearest earlier agents. Minimally
 * rigid for generic positions, which random ones are with probability 1 (make_scenario checks
 * the rank anyway). Deterministic for a seed on every platform (mt19937_64, own sampling).
 * @throws InvalidInput naming --agents (n >= d + 1), --dimension (2 or 3) or --spacing.
 */
FormationGraph hennebergConstruction(int agents, int dimension, std::uint64_t seed, double spacing);

/**
 * Initial positions q*_i + u_i with every coordinate of u_i drawn uniformly from
 * [-sigma, sigma] (so |u_i| <= sigma sqrt(d)). Deterministic for a seed on every platform.
 * @param sigma [m], >= 0; 0 returns the desired positions.
 * @throws InvalidInput naming --perturb if sigma is negative or not finite.
 */
Positions perturbedPositions(const Positions& desired, double sigma, std::uint64_t seed);

}  // namespace vf
