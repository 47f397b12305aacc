#pragma once

#include <memory>
#include <string>
#include <utility>

#include "variational_formation_core/model/force_model.hpp"
#include "variational_formation_core/model/formation.hpp"
#include "variational_formation_core/integrators/variational_update.hpp"

namespace vf {

class SafetyStage;

/// Which scheme integrates the closed loop q'' = -kappa q' - grad V (paper eq. (formation3)).
enum class Method { Variational, ExplicitEuler, RungeKutta4 };

/// "vi", "euler", "rk4" -> Method. @throws InvalidInput naming `field`.
Method parseMethod(const std::string& text, const std::string& field = "--method");
/// "variational", "paper" -> StartMethod. @throws InvalidInput naming `field`.
StartMethod parseStartMethod(const std::string& text, const std::string& field = "--init");

/**
 * A one-step view of every integrator: state at step k, advanced by step(). The step index
 * k starts at 0 with the initial positions; time is k h.
 */
class Integrator {
 public:
  virtual ~Integrator() = default;

  /// Advances from step k to step k + 1.
  virtual void step() = 0;
  /// q_k, d x n.
  virtual const Positions& positions() const = 0;
  /// Velocity at step k: v_{k-1} = (q_k - q_{k-1})/h for the variational scheme (v_0 at k = 0).
  virtual Velocities velocities() const = 0;
  /// Unweighted momentum at step k: p+_k for the variational scheme (v_0 at k = 0), v_k else.
  virtual Momenta momenta() const = 0;
  /// Energy at step k: the discrete energy E_d(q_{k-1}, q_k) for the variational scheme,
  /// 1/2|v|^2 + V(q) otherwise (and at k = 0).
  virtual double energy() const = 0;
  /// The scale s the desired distances are multiplied by at step k (1 without a manoeuvre).
  virtual double commandedScale() const { return 1.0; }

  /**
   * Sends every later step through the safety filter (doc/maths.md §10): the force model's step
   * filter. Only the variational integrators (plain and under commands) apply it; without one,
   * today's steps bit for bit.
   */
  void attachSafety(std::shared_ptr<SafetyStage> stage) { forces_.setStepFilter(std::move(stage)); }
  /// The attached filter, or nullptr.
  SafetyStage* safety() const { return forces_.stepFilter(); }

  /// What acts on the agents (force_model.hpp): the formation potential, added terms, the filter.
  ForceModel& forceModel() { return forces_; }
  const ForceModel& forceModel() const { return forces_; }

  long stepIndex() const { return step_; }
  double time() const { return static_cast<double>(step_) * timeStep_; }
  double timeStep() const { return timeStep_; }
  const Formation& formation() const { return formation_; }

 protected:
  Integrator(const Formation& formation, double timeStep, double dampingGain)
      : formation_(formation), forces_(formation), timeStep_(timeStep), dampingGain_(dampingGain) {}

  const Formation& formation_;
  ForceModel forces_;  // every step's forces go through it
  double timeStep_;
  double dampingGain_;
  long step_ = 0;
};

/**
 * Builds an integrator. The formation must outlive it.
 * @param q0 initial positions, @param v0 initial velocities (d x n each).
 * @param timeStep h > 0 [s]. @param dampingGain kappa >= 0 [1/s].
 * @param start only used by Method::Variational.
 * @throws InvalidInput on bad sizes or values (h and kappa: validateDynamics, validation.hpp).
 */
std::unique_ptr<Integrator> makeIntegrator(Method method, const Formation& formation,
                                           const Positions& q0, const Velocities& v0,
                                           double timeStep, double dampingGain,
                                           StartMethod start = StartMethod::Variational);

}  // namespace vf
