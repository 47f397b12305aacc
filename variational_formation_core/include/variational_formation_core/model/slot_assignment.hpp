#pragma once

#include <string>
#include <vector>

#include "variational_formation_core/model/rigid_fit.hpp"

namespace vf {

/**
 * Which agent takes which desired position (slot), and the rigid motion of the desired shape
 * that goes with it (doc/scenarios.md, "Slot assignment").
 */
struct SlotAssignment {
  std::vector<int> slotOfAgent;  ///< slot (the scenario file's index of a desired position) of agent i
  RigidFit motion;               ///< x -> R x + t applied to the desired shape
  double cost = 0.0;             ///< sum_i |q0_i - (R q*_slot(i) + t)|^2 [m^2]
  double costAsGiven = 0.0;      ///< the same for the identity and its best rigid motion [m^2]
  /// One line: "agent -> slot 0->3 1->0 ...; rotation 30 deg, translation (x, y) m, ...".
  std::string describe() const;
};

/**
 * The permutation and rigid motion (rotation and translation, a reflection only if
 * allowReflection; no scaling) that minimise the total squared distance from the starts to
 * the moved desired positions, sum_i |q0_i - (R q*_slot(i) + t)|^2.
 *
 * Alternates the Hungarian method (the best permutation for the motion) with Procrustes (the
 * best motion for the permutation) until the permutation repeats; each alternation lowers the
 * cost, so it ends, at a local optimum. It starts from several rotations about the centroids
 * (2D: the 8 multiples of 45 deg; 3D: the 24 rotations of the cube; with reflections allowed,
 * each also composed with a mirror) and keeps the lowest cost; a later start must be lower by
 * more than 1e-12 relative to replace an earlier one, so ties go to the first start.
 * Deterministic: the same inputs give the same assignment on every agent.
 * @param starts q0, d x n [m]; @param desired q*, d x n [m].
 * @throws InvalidInput if the sizes differ.
 */
SlotAssignment assignSlots(const Positions& starts, const Positions& desired, bool allowReflection);

}  // namespace vf
