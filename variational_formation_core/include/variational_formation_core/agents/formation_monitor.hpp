#pragma once

#include <map>
#include <string>
#include <vector>

#include "variational_formation_core/manoeuvres/command_schedule.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/model/shape_outcome.hpp"
#include "variational_formation_core/integrators/step_metrics.hpp"
#include "variational_formation_core/integrators/variational_update.hpp"

namespace vf {

/// Everything the monitor publishes for a completed step.
struct FormationSnapshot {
  StepMetrics metrics;                 ///< energy, max distance error, momenta
  Vector3 linearMomentumPredicted;     ///< e^{-kappa t_k} P_0
  Vector3 angularMomentumPredicted;    ///< e^{-kappa t_k} A_0
  Eigen::VectorXd agentEnergy;
  Eigen::VectorXd edgeDistanceErrors;   ///< |q_i - q_j| - s d_ij per edge
  double scale = 1.0;                  ///< s, the commanded scale the step is measured against
  Positions positions;                 ///< q_k, d x n
  bool congruent = false;              ///< every pair within 1% of s d_ij and every agent slow (moving as commanded), either hand
  long congruentSince = -1;            ///< first step of the current congruent stretch, -1 if not congruent
  /// In the desired shape at this step: congruent, and not a mirror image that the scenario
  /// forbids (`mirror: forbidden`, the default). The one meaning of "converged" (ShapeOutcome).
  bool converged = false;
  long convergedStep = -1;             ///< first step of the current converged stretch, -1 if not converged
  /// Shape error over all pairs, edges converged, mirror image (shape_outcome.hpp). The O(n^2)
  /// shape error is measured when shapeErrorMeasuredAt says (every step up to 50 agents, beyond
  /// that every ceil((n/50)^2) steps and at the last one; NaN between). The mirror test runs at
  /// the first step of a congruent stretch, whose answer the later steps of the stretch keep.
  ShapeFindings shape;
};

/**
 * The monitor's core: collects agents' states (q_k, q_{k-1}) by step and, for each step that
 * every agent has reported, computes the metrics exactly as VariationalIntegrator::momenta()
 * and energy() define them (p+_k and E_d(q_{k-1}, q_k); v_0 and the continuous energy at
 * k = 0), so they match `simulate --metrics`; under commands the distances, energy and congruence
 * are the commanded ones (setSchedule).
 */
class FormationMonitor {
 public:
  explicit FormationMonitor(const Scenario& scenario, double tolerance = 0.01, double maxSpeed = 0.1);

  /// What became of an offered state.
  enum class Receipt { Accepted, Duplicate, UnknownAgent, WrongDimension, NonFinite, ImpossibleStep };
  static std::string describe(Receipt receipt);

  /// Stores agent `id`'s state at `step` unless it is invalid (stores nothing then) or already
  /// held or completed (Duplicate). Steps past `lastAllowed` are impossible: the agents never
  /// compute them, which bounds what is buffered.
  Receipt add(long id, long step, const std::vector<double>& position, const std::vector<double>& previousPosition,
              long lastAllowed);
  /**
   * Starts at `step` instead of 0 (a restarted monitor): the steps before it count as completed,
   * and `congruentSince` is the first step of the converged stretch holding at step - 1 (-1 if
   * none: a stretch in a forbidden mirror image is not carried over, and starts again at `step`).
   * Requires that nothing was added yet.
   */
  void startAt(long step, long congruentSince);
  /// Agents whose state at `step` has not arrived (all of them if none has).
  std::vector<int> missingAt(long step) const;
  /// Completed steps in order, each removed from the buffer once returned.
  std::vector<FormationSnapshot> takeCompleted();

  /**
   * The commanded motion the agents apply (protocol::appliedSchedule; at first the scenario's
   * `manoeuvre:`). Step k is measured under the command of interval k - 1 (interval 0 at k = 0):
   * distances against s d_ij, energy with V_s, and congruence with the velocities relative to the
   * commanded motion v* + omega* x (q_i - c), c the centroid. Steps already measured keep theirs.
   */
  void setSchedule(const CommandSchedule& schedule) { schedule_ = schedule; }

  long nextStep() const { return next_; }
  const Formation& formation() const { return formation_; }
  const Scenario& scenario() const { return scenario_; }

 private:
  FormationSnapshot measureStep(long step, const Positions& qPrev, const Positions& q);

  struct Pending {
    Positions q, qPrev;
    std::vector<bool> seen;
    int count = 0;
  };
  Scenario scenario_;
  Formation formation_;
  VariationalCoefficients coefficients_;
  CommandSchedule schedule_;
  double tolerance_, maxSpeed_;
  CongruenceTracker congruence_;  // isCongruent at amortised O(n) per step
  std::map<long, Pending> pending_;
  long next_ = 0;
  long congruentSince_ = -1;
  bool mirrorTested_ = false;  // the mirror test ran in the current congruent stretch; its answer:
  bool mirrored_ = false;
  Vector3 p0_, a0_;
};

}  // namespace vf
