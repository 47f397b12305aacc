#pragma once

#include <memory>
#include <utility>
#include <vector>

#include "variational_formation_core/model/formation.hpp"
#include "variational_formation_core/model/motion_parameters.hpp"

namespace vf {

class SafetyStage;

/**
 * A potential term W added to the formation potential (a repulsion, an obstacle field): what the
 * force model sums after V. Agent i's gradient may read any column of q, so a term that reads
 * more than agent i's formation neighbours needs those agents' states in a distributed run
 * (doc/architecture.md, "The force model").
 */
class PotentialTerm {
 public:
  virtual ~PotentialTerm() = default;
  /// W(q) [m^4/s^2 like V, per unit mass].
  virtual double potential(const Positions& q) const = 0;
  /// Adds grad_i W(q) to out (d doubles) [m/s^2 per m of the update's gain].
  virtual void addAgentGradient(int agent, const Positions& q, double* out) const = 0;
  /// W(q + t) = W(q) for every translation t (then sum_i grad_i W = 0: linear momentum, Noether).
  virtual bool translationInvariant() const = 0;
  /// W(R q) = W(q) for every rotation R about the origin (then sum_i q_i x grad_i W = 0).
  virtual bool rotationInvariant() const = 0;
};

/**
 * The force model: everything that acts on an agent in the variational update, in the terms of
 * the discrete Lagrange-d'Alembert principle (doc/maths.md §2, §9, §10):
 *  - the potential's gradient grad_i V, V the formation potential (paper eq. (eq: Vij)), V_s
 *    under a commanded scale s, plus any added PotentialTerm, summed after V in the order added;
 *  - the state-dependent part of the forcing F under a command: agent i's centroid offset r_i;
 *  - the step filter (the safety filter), applied to every agent's q^{k+2} after the update.
 * Every integrator, agent and campaign asks this class, never Formation directly, so a new
 * interaction is one PotentialTerm and a new filter one stage. With only the formation potential
 * it performs exactly Formation's operations: bit for bit today's numbers.
 *
 * Per-agent calls are non-virtual for V; an added term costs one virtual call per agent (none per
 * edge). Copies share the formation, the terms and the filter.
 */
class ForceModel {
 public:
  /// The formation potential alone, not owned: `formation` must outlive the model.
  explicit ForceModel(const Formation& formation)
      : formation_(std::shared_ptr<const Formation>(), &formation) {}
  /// The formation potential alone, shared.
  explicit ForceModel(std::shared_ptr<const Formation> formation) : formation_(std::move(formation)) {}

  const Formation& formation() const { return *formation_; }
  int dimension() const { return formation_->dimension(); }
  int agentCount() const { return formation_->agentCount(); }

  /// Adds W to the potential (after V and the terms added before).
  void addTerm(std::shared_ptr<const PotentialTerm> term) { terms_.push_back(std::move(term)); }
  const std::vector<std::shared_ptr<const PotentialTerm>>& terms() const { return terms_; }

  /**
   * grad_i (V + sum W)(q) into out (d doubles): Formation::agentGradient, then each term's.
   * Reads column i and, for V, the columns of N_i.
   */
  void agentGradient(int agent, const Positions& q, double* out) const {
    formation_->agentGradient(agent, q, out);
    addTerms(agent, q, out);
  }
  /// Under a commanded scale: grad_i (V_s + sum W)(q), s^2 = scaleSquared [1] (doc/maths.md §9).
  void agentGradient(int agent, const Positions& q, double scaleSquared, double* out) const {
    formation_->agentScaledGradient(agent, q, scaleSquared, out);
    addTerms(agent, q, out);
  }
  /// Stacked gradient, d x n, agent by agent through agentGradient.
  void gradient(const Positions& q, Gradients& out) const;
  /// (V_s + sum W)(q) [m^4/s^2 per unit mass]; s^2 = scaleSquared (1: V itself).
  double potential(const Positions& q, double scaleSquared = 1.0) const;

  /// The forcing's state-dependent part: r_i = sum_j mu_ij (q_i - q_j) [m] (motion_parameters.hpp).
  void centroidOffset(const MotionParameters& parameters, int agent, const Positions& q, double* out) const {
    vf::centroidOffset(*formation_, parameters, agent, q, out);
  }

  /// Whether the whole potential is invariant under translations / rotations about the origin
  /// (V is both; each term says for itself). Noether: the momentum the symmetry conserves.
  bool translationInvariant() const;
  bool rotationInvariant() const;

  /**
   * The fast path of a campaign (RoaCampaign): grad (V + sum W) of `Lanes` configurations side by
   * side, coordinate a of agent i in lane l at [(i d + a) Lanes + l] in q and in gradient. V is
   * scattered edge by edge so that each agent's terms arrive in the order agentGradient sums
   * them; the terms follow per lane through agentGradient's own calls. Bit-identical to
   * agentGradient lane by lane.
   */
  template <int Lanes>
  void laneGradient(const double* q, double* gradient) const;

  /// Attaches the step filter (nullptr: none; doc/maths.md §10).
  void setStepFilter(std::shared_ptr<SafetyStage> filter) { filter_ = std::move(filter); }
  SafetyStage* stepFilter() const { return filter_.get(); }
  /**
   * Filters every agent's qNext (q^{k+2}, d x n) given q = q^{k+1}, the positions at `step`; does
   * nothing without a filter. Call after every agent's update (SafetyStage::apply).
   */
  void filterStep(const Positions& q, long step, Positions& qNext) const;

 private:
  void addTerms(int agent, const Positions& q, double* out) const {
    for (const auto& term : terms_) term->addAgentGradient(agent, q, out);
  }

  std::shared_ptr<const Formation> formation_;
  std::vector<std::shared_ptr<const PotentialTerm>> terms_;
  std::shared_ptr<SafetyStage> filter_;
};

}  // namespace vf
