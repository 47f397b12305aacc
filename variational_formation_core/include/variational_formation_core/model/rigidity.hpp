#pragma once

#include <cstdint>
#include <string>

#include "variational_formation_core/model/formation.hpp"

namespace vf {

/// The generic rigidity class of a graph in R^d, from the weakest to the strongest. A graph has
/// the strongest class whose property holds (a triangle is globally rigid, and minimally rigid too).
enum class RigidityClass {
  NotRigid,          ///< flexible: some motion keeps every edge length
  Rigid,             ///< rigid, with more edges than needed, yet some edge is necessary
  MinimallyRigid,    ///< rigid with exactly dn - d(d+1)/2 edges (every edge necessary)
  RedundantlyRigid,  ///< still rigid after removing any one edge, not globally rigid
  GloballyRigid,     ///< the edge lengths fix every pair distance (the shape, up to a mirror image)
};

/// "not rigid", "rigid", "minimally rigid", "redundantly rigid", "globally rigid".
std::string describe(RigidityClass rigidityClass);

/// What classifyRigidity found, on the realization that decided the class.
struct RigidityReport {
  RigidityClass rigidityClass = RigidityClass::NotRigid;
  int dimension = 0;
  int agents = 0;
  int edges = 0;
  int rank = 0;            ///< rank of the rigidity matrix at a generic realization
  int neededRank = 0;      ///< dn - d(d+1)/2 (n >= d + 1), or n(n-1)/2 (n <= d + 1)
  int stresses = 0;        ///< dimension of the space of equilibrium stresses, |E| - rank
  int stressRank = -1;     ///< rank of a generic stress matrix (-1: no stress or n <= d + 1)
  bool rigid = false, minimallyRigid = false, redundantlyRigid = false, globallyRigid = false;
  /// One line: "minimally rigid in 2D (6 agents, 9 edges; rigidity rank 9 of 9; ...)".
  std::string summary() const;
};

/**
 * Classifies the graph of `formation` (its edges; its desired positions are not used) in its
 * dimension d = 2 or 3, generically, by numerical tests on random realizations (Gaussian
 * coordinates from `seed`, deterministic):
 * - rigid iff rank R = dn - d(d+1)/2 for n >= d + 1; for n <= d + 1, iff every pair is an edge;
 * - redundantly rigid iff rigid and every edge carries some equilibrium stress (a row of R in
 *   the span of the others, so removing it keeps the rank);
 * - globally rigid (n >= d + 2) iff a random equilibrium stress, a random combination of a basis
 *   of the left null space of R, has a stress matrix of rank n - d - 1 (Connelly's sufficient
 *   condition; Gortler, Healy & Thurston 2010 show it is necessary for generic frameworks);
 *   for n <= d + 1, iff complete.
 * Three realizations are classified and the majority class is kept (the middle class if all
 * three differ), so one ill-conditioned draw cannot decide. Cost: a full SVD of the |E| x dn
 * rigidity matrix per realization, O(|E|^3).
 */
RigidityReport classifyRigidity(const Formation& formation, std::uint64_t seed = 1);

/// Largest formation the tools classify unasked (scenario_info, make_scenario's comment): the
/// test is O(|E|^3), and scenario_info runs at every launch.
constexpr int kMaxClassifiedAgents = 100;

}  // namespace vf
