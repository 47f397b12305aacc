#pragma once

#include <memory>
#include <vector>

#include "variational_formation_core/model/force_model.hpp"
#include "variational_formation_core/model/motion_parameters.hpp"
#include "variational_formation_core/model/scenario.hpp"

namespace vf {

/**
 * What one agent of a distributed run knows of the formation (doc/distributed.md): its initial state,
 * its neighbours, the checks of a neighbour's state message, and grad_i V from the positions it
 * holds, through the force model (ForceModel::agentGradient) exactly as the centralised
 * integrators call it.
 */
class AgentNeighbourhood {
 public:
  /// Why a neighbour's state cannot be used.
  enum class StateCheck { Usable, UnknownSender, WrongDimension, NonFinite };

  /**
   * @param formation makeFormation(scenario), shared with other agents; nullptr: one of its own.
   * @throws InvalidInput if id is not an agent of the (validated) scenario, or `formation` is
   * not of the scenario's size.
   */
  AgentNeighbourhood(const Scenario& scenario, int id, std::shared_ptr<const Formation> formation = nullptr);

  int id() const { return id_; }
  int dimension() const { return model_.dimension(); }
  /// What acts on this agent (the formation potential; its neighbours' positions are all it reads).
  const ForceModel& forceModel() const { return model_; }
  /// N_i in the order of the scenario's edges.
  const std::vector<int>& neighbourIds() const { return neighbourIds_; }
  /// q_0 and v_0 of the scenario [m], [m/s].
  const std::vector<double>& initialPosition() const { return q0_; }
  const std::vector<double>& initialVelocity() const { return v0_; }

  /// A state (q, q_prev) from `sender`: a neighbour's, d finite values each.
  StateCheck check(long sender, const std::vector<double>& position,
                   const std::vector<double>& previousPosition) const;

  /**
   * grad_i V(q) (doc/maths.md §2) from the agent's own q_i and the neighbours' positions.
   * @param own d doubles. @param neighbourPosition(j) d doubles of neighbour j.
   * @param out d doubles.
   */
  template <class NeighbourPosition>
  void gradient(const double* own, NeighbourPosition neighbourPosition, double* out) {
    if (model_.terms().empty()) {  // V alone reads only N_i: straight from the held positions
      model_.formation().agentGradientFrom(id_, own, neighbourPosition, out);
      return;
    }
    view(own, neighbourPosition);
    model_.agentGradient(id_, view_, out);
  }

  /**
   * Under a command (doc/maths.md §9): grad_i V_s with s^2 = scaleSquared into `gradient`, and,
   * if `rotates`, the agent's centroid offset r_i into `offset` (d doubles each), from the same
   * positions as gradient().
   */
  template <class NeighbourPosition>
  void forcedGradient(const double* own, NeighbourPosition neighbourPosition, double scaleSquared, bool rotates,
                      double* gradient, double* offset) {
    if (model_.terms().empty()) {
      model_.formation().agentScaledGradientFrom(id_, own, neighbourPosition, scaleSquared, gradient);
      if (rotates) centroidOffsetFrom(model_.formation(), motion_, id_, own, neighbourPosition, offset);
      return;
    }
    view(own, neighbourPosition);
    model_.agentGradient(id_, view_, scaleSquared, gradient);
    if (rotates) model_.centroidOffset(motion_, id_, view_, offset);
  }
  /// Whether this agent knows its offset from the centroid from its neighbours (it can turn),
  /// and if not, why.
  const MotionParameters& motion() const { return motion_; }

 private:
  /// The agent's and its neighbours' positions into view_ (made at the first call: only a model
  /// with added terms, which may read any column, needs it).
  template <class NeighbourPosition>
  void view(const double* own, NeighbourPosition neighbourPosition) {
    const int d = dimension();
    if (view_.cols() == 0) view_ = Positions::Zero(d, model_.agentCount());
    for (int a = 0; a < d; ++a) view_(a, id_) = own[a];
    for (int j : neighbourIds_) {
      const double* qj = neighbourPosition(j);
      for (int a = 0; a < d; ++a) view_(a, j) = qj[a];
    }
  }

  ForceModel model_;  // owns the scenario's formation: agents are moved into vectors
  int id_;
  std::vector<int> neighbourIds_;
  std::vector<double> q0_, v0_;
  Positions view_;  // with added terms: positions of self and neighbours, d x n (other columns unused)
  MotionParameters motion_;
};

}  // namespace vf
