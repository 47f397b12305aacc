#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "variational_formation_core/agents/agent_neighbourhood.hpp"
#include "variational_formation_core/manoeuvres/manoeuvre_model.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/safety/timed_safety.hpp"
#include "variational_formation_core/integrators/variational_update.hpp"

namespace vf {

/**
 * One agent of the time-driven mode, without any transport. Unlike LockstepAgent it never waits:
 * tick(now) is called on every wall-clock tick (period h / rate) and computes q_{k+1} from its
 * own state and the NEWEST position received from each neighbour, with the same core functions
 * as LockstepAgent (Formation::agentGradient, variationalUpdate, variationalStart). When every
 * neighbour's newest state is the one of the previous tick, the trajectory is the centralised
 * one bit for bit.
 *
 * Holding: if a neighbour has never been heard, or its newest state was received more than
 * maxAge seconds ago, the agent does not move (q_{k+1} = q_k). After a hold it restarts from rest
 * with the variational start (v = 0); holds before the first move only defer the start from the
 * scenario's (q_0, v_0). The step k counts ticks, holds included, so that the agent's state
 * messages keep advancing while it holds and its neighbours do not take it for silent.
 *
 * Robot mode: setMeasuredPosition(q) makes the next tick start from the measured position, with
 * the velocity taken from the agent's own previous command (velocity form of the update,
 * doc/robots.md), so that measurement noise is never divided by h.
 *
 * Safety (a scenario with `safety:`, enableSafety): the agent keeps every other agent's newest
 * position, not only its neighbours', and filters each step with them (TimedSafety, doc/robots.md
 * "Safety"); it holds until it has heard every agent once.
 *
 * Times (`now`, receive and send times, ages, maxAge) are in seconds on one clock of the caller's choice.
 */
class TimedAgent {
 public:
  /// What became of a received neighbour state.
  enum class Receipt { Accepted, Outdated, UnknownSender, WrongDimension, NonFinite, NegativeStep };

  /// One neighbour as the agent sees it at some time.
  struct NeighbourStatus {
    int id = -1;
    bool heard = false;  ///< a state was ever accepted
    long step = -1;      ///< the neighbour's step of the newest accepted state
    double age = 0.0;    ///< now - its local receive time [s]; +inf if never heard
    bool stale = true;   ///< never heard, or age > maxAge
    long accepted = 0;   ///< states accepted from it
    long dropped = 0;    ///< states from it that were not accepted (outdated, malformed)
  };

  /// What a tick did.
  struct TickResult {
    long step = 0;         ///< the agent's step after the tick
    bool holding = false;  ///< it did not move, because of the neighbours in `stale`
    std::vector<NeighbourStatus> stale;  ///< neighbours never heard or older than maxAge
  };

  /**
   * @param scenario a validated scenario. @param id the agent's id.
   * @param maxAge [s] > 0: a neighbour whose newest state is older than this makes the agent hold.
   * @throws InvalidInput on a bad id or maxAge.
   */
  TimedAgent(const Scenario& scenario, int id, double maxAge, StartMethod start = StartMethod::Variational);

  /**
   * Offers neighbour `sender`'s state at its step m (q_m, q_{m-1}), received at local time `now`.
   * Accepted if it is the first, or if its step is higher than the held one's, or if the held
   * one is older than maxAge (a neighbour back from silence, for instance after a respawn, may
   * restart from a lower step). Anything else is Outdated (a reordered or repeated message).
   * Never changes the agent's own state. With safety on, a state of any other agent of the
   * formation is kept for the filter (with its send time `sentAt` [s], `now` if NaN), and a
   * non-neighbour's is then Accepted (not UnknownSender).
   */
  Receipt receive(long sender, long step, const std::vector<double>& position,
                  const std::vector<double>& previousPosition, double now,
                  double sentAt = std::numeric_limits<double>::quiet_NaN());

  /**
   * Turns the safety filter on. @param scenario the agent's (with a safety block).
   * @param maxSpeed [m/s] (timedSafetySpeed). @param handOffset [m], 0 for holonomic robots.
   * @throws InvalidInput without a safety block or on a bad value.
   */
  void enableSafety(const Scenario& scenario, double maxSpeed, double handOffset);
  /// The filter, or nullptr without safety.
  const TimedSafety* safety() const { return safety_ ? &*safety_ : nullptr; }
  /// Half-spaces and speed limit that bound the last tick's step (0 when it held or nothing bound).
  int constraintsActive() const { return constraintsActive_; }
  /// With safety on: also keep r from other formations' agents (TimedSafety::avoid). Call after enableSafety.
  void avoid(std::shared_ptr<const ForeignAgents> foreign) {
    if (safety_) safety_->avoid(std::move(foreign));
  }
  /// Of constraintsActive(), the half-spaces of other formations' agents.
  int foreignConstraintsActive() const { return foreignConstraintsActive_; }

  /// One wall-clock tick at time `now`: q_k -> q_{k+1}, or a hold. Never blocks.
  TickResult tick(double now);

  /**
   * Robot mode: the position measured at the coming tick [m], d values. The next tick starts
   * from it, with the velocity state v_k from the agent's own previous command. Used once.
   * @throws InvalidInput on a wrong size or a non-finite value.
   */
  void setMeasuredPosition(const std::vector<double>& position);

  /**
   * A commanded motion (v*, omega*, s; doc/manoeuvres.md) from the next tick on, replacing the
   * scenario's `manoeuvre:` (which otherwise applies by the agent's own step). The update is the
   * forced one of doc/maths.md §9 with the node gains of the previous tick's command and this one.
   * @throws InvalidInput if validateCommand refuses it or it turns and this agent cannot know its
   * offset from the centroid; the agent's command is then unchanged.
   */
  void setCommand(const Command& command);
  /// The command of the coming tick (zero without any).
  Command command() const;

  /**
   * kappa [1/s] (dynamic_reconfigure): recomputes the update coefficients; the velocity state
   * is kept. @throws InvalidInput if validateDynamics refuses kappa at the scenario's h (as in a
   * scenario file; refuseDampingGain words the refusal for a node's log).
   */
  void setDampingGain(double dampingGain);

  /**
   * Restarts from a known position at a given step (a respawned agent that recovered its own
   * newest state), at rest. @throws InvalidInput on a wrong size, non-finite value or step < 0.
   */
  void restore(long step, const std::vector<double>& position);

  int id() const { return neighbourhood_.id(); }
  /// Ticks so far, holds included.
  long step() const { return step_; }
  /// scenario steps reached (never for steps = 0, unbounded).
  bool finished() const { return steps_ > 0 && step_ >= steps_; }
  /// The last tick held.
  bool holding() const { return holding_; }
  /// q_k [m]: after a tick, the new position; in robot mode, the position setpoint q_{k+1}.
  const std::vector<double>& position() const { return q_; }
  /// q_{k-1} [m] (the measured position the last update started from, in robot mode).
  const std::vector<double>& previousPosition() const { return qPrev_; }
  /// The position setpoint for the robot [m]: same as position().
  const std::vector<double>& positionSetpoint() const { return q_; }
  /// v_k [m/s] = (q_{k+1} - q_k) / h of the last tick: the commanded velocity; 0 while holding.
  const std::vector<double>& commandedVelocity() const { return v_; }
  double dampingGain() const { return coefficients_.dampingGain; }
  double timeStep() const { return coefficients_.timeStep; }
  double maxAge() const { return maxAge_; }
  const std::vector<int>& neighbourIds() const { return neighbourhood_.neighbourIds(); }
  /// Every neighbour's status at time `now` [s], in neighbourIds() order.
  std::vector<NeighbourStatus> neighbourStatus(double now) const;
  long accepted() const { return accepted_; }
  /// States refused, for any reason, from any sender.
  long dropped() const { return dropped_; }
  /// Ticks that held.
  long heldTicks() const { return heldTicks_; }

  static std::string describe(Receipt receipt);

 private:
  struct NeighbourState {
    bool heard = false;
    long step = -1;
    double receivedAt = 0.0;
    long accepted = 0;
    long dropped = 0;
    std::vector<double> position;
    std::vector<double> previousPosition;
  };
  NeighbourStatus status(int j, double now) const;
  Receipt accept(long sender, long step, const std::vector<double>& position,
                 const std::vector<double>& previousPosition, double now);
  void hold();
  /// The update (or start) with the gradient and, under a command, the forcing `g` and offset.
  void move(const double* gradient, const ManoeuvreGains* g, const double* offset);

  AgentNeighbourhood neighbourhood_;
  VariationalCoefficients coefficients_;
  StartMethod start_;
  long steps_;  // the scenario's, 0 = unbounded
  int dimension_;
  double maxAge_;
  long step_ = 0;
  bool started_ = false;   // moved at least once: the next move is an update, not a start
  bool restart_ = false;   // held since the last move: the next move starts from rest
  bool holding_ = false;
  bool measured_ = false;  // robot mode: qMeasured_ is the position of the coming tick
  long heldTicks_ = 0;
  long accepted_ = 0;
  long dropped_ = 0;
  std::vector<double> qPrev_, q_, v_, qMeasured_;
  std::vector<NeighbourState> neighbours_;  // indexed by agent id (only neighbours used)
  CommandSchedule schedule_;  // the scenario's manoeuvre (empty: none)
  bool live_ = false;         // a command came: it applies instead of the schedule
  Command liveCommand_;
  bool haveLastGains_ = false;  // the previous move's interval gains (for the node gains)
  ManoeuvreGains lastGains_;
  std::optional<TimedSafety> safety_;  // empty: no safety block, or not enabled
  double tickNow_ = 0.0;                 // the current tick's time, for the filter's margins
  int constraintsActive_ = 0, foreignConstraintsActive_ = 0;
};

}  // namespace vf
