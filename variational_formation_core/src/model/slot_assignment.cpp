#include "variational_formation_core/model/slot_assignment.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/hungarian.hpp"

namespace vf {

namespace {

constexpr int kMaxAlternations = 100;  // each strictly lowers the cost; in practice a handful

/// The starting rotations: 2D multiples of 45 deg; 3D the cube's 24 rotations.
std::vector<Eigen::MatrixXd> startingRotations(int d) {
  std::vector<Eigen::MatrixXd> rotations;
  if (d == 2) {
    for (int k = 0; k < 8; ++k) {
      const double angle = 0.7853981633974483 * k;  // pi/4 k
      Eigen::MatrixXd r(2, 2);
      r << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
      rotations.push_back(r);
    }
    return rotations;
  }
  // Signed permutation matrices with determinant +1.
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& p : perms) {
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::MatrixXd r = Eigen::MatrixXd::Zero(3, 3);
      for (int row = 0; row < 3; ++row) r(row, p[row]) = (signs >> row & 1) ? -1.0 : 1.0;
      if (r.determinant() > 0.0) rotations.push_back(r);
    }
  }
  return rotations;
}

/// Hungarian and Procrustes in turn from one starting motion.
SlotAssignment descend(const Positions& starts, const Positions& desired, RigidFit motion, bool allowReflection) {
  const int n = static_cast<int>(starts.cols());
  SlotAssignment best;
  for (int round = 0; round < kMaxAlternations; ++round) {
    const Positions moved = (motion.rotation * desired).colwise() + motion.translation;
    Eigen::MatrixXd cost(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) cost(i, j) = (starts.col(i) - moved.col(j)).squaredNorm();
    const std::vector<int> slots = minimumCostAssignment(cost);
    if (slots == best.slotOfAgent) break;
    Positions taken(desired.rows(), n);
    for (int i = 0; i < n; ++i) taken.col(i) = desired.col(slots[i]);
    motion = fitRigidMotion(starts, taken, allowReflection);
    if (!best.slotOfAgent.empty() && !(motion.squaredResidual < best.cost)) break;
    best.slotOfAgent = slots;
    best.motion = motion;
    best.cost = motion.squaredResidual;
  }
  return best;
}

}  // namespace

SlotAssignment assignSlots(const Positions& starts, const Positions& desired, bool allowReflection) {
  if (starts.rows() != desired.rows() || starts.cols() != desired.cols() || starts.cols() == 0) {
    throw InvalidInput("assignment: the starts and the desired positions differ in size");
  }
  const int d = static_cast<int>(starts.rows());
  const Eigen::VectorXd startCentroid = starts.rowwise().mean(), desiredCentroid = desired.rowwise().mean();
  Eigen::MatrixXd mirror = Eigen::MatrixXd::Identity(d, d);
  mirror(d - 1, d - 1) = -1.0;
  std::vector<Eigen::MatrixXd> rotations = startingRotations(d);
  if (allowReflection) {
    const std::size_t proper = rotations.size();
    for (std::size_t k = 0; k < proper; ++k) rotations.push_back(rotations[k] * mirror);
  }
  SlotAssignment best;
  for (const Eigen::MatrixXd& rotation : rotations) {
    RigidFit start;
    start.rotation = rotation;
    start.translation = startCentroid - rotation * desiredCentroid;
    const SlotAssignment candidate = descend(starts, desired, start, allowReflection);
    if (best.slotOfAgent.empty() || candidate.cost < best.cost - 1e-12 * std::max(1.0, best.cost)) best = candidate;
  }
  best.costAsGiven = fitRigidMotion(starts, desired, allowReflection).squaredResidual;
  return best;
}

std::string SlotAssignment::describe() const {
  std::string line = "agent -> slot";
  for (std::size_t i = 0; i < slotOfAgent.size(); ++i) {
    line += " " + std::to_string(i) + "->" + std::to_string(slotOfAgent[i]);
  }
  char text[200];
  const int d = static_cast<int>(motion.rotation.rows());
  if (d == 2) {
    const double angle = std::atan2(motion.rotation(1, 0), motion.rotation(0, 0)) * 57.29577951308232;
    std::snprintf(text, sizeof text, "; %s %.1f deg, translation (%.3f, %.3f) m", motion.reflection ? "mirror and rotation" : "rotation",
                  angle, motion.translation(0), motion.translation(1));
  } else {
    const double trace = motion.rotation.trace() * (motion.reflection ? -1.0 : 1.0);
    const double angle = std::acos(std::max(-1.0, std::min(1.0, 0.5 * (trace - 1.0)))) * 57.29577951308232;
    std::snprintf(text, sizeof text, "; %s %.1f deg, translation (%.3f, %.3f, %.3f) m",
                  motion.reflection ? "mirror and rotation" : "rotation", angle, motion.translation(0),
                  motion.translation(1), motion.translation(2));
  }
  line += text;
  std::snprintf(text, sizeof text, "; total squared distance %.4g m^2 (%.4g as given)", cost, costAsGiven);
  return line + text;
}

}  // namespace vf
