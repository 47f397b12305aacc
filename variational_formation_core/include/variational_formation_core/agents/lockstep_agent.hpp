#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "variational_formation_core/manoeuvres/manoeuvre_model.hpp"
#include "variational_formation_core/agents/agent_neighbourhood.hpp"
#include "variational_formation_core/safety/foreign_agents.hpp"
#include "variational_formation_core/safety/safety_filter.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/agents/sensing_board.hpp"
#include "variational_formation_core/integrators/variational_update.hpp"

namespace vf {

/**
 * One agent of the distributed lockstep run (doc/distributed.md), without any transport: it holds
 * q_{k-1}, q_k of its own and the latest state of each neighbour, and computes q_{k+1} once
 * it holds every neighbour's q_k. It calls Formation::agentGradient and variationalUpdate /
 * variationalStart exactly as VariationalIntegrator does, so the distributed trajectory equals
 * the centralised one bit for bit.
 *
 * Neighbour states arrive as (step m, q_m, q_{m-1}). A neighbour is never more than one step
 * ahead (it needs our q_m to get past m), so a state at m = k + 1 still carries the q_k we need:
 * a lost or late message is made good by the next one.
 *
 * With the scenario's `safety:` block every step also goes through the safety filter
 * (doc/maths.md §10) with the agents within the sensing radius, as SafetyStage applies it: the
 * agent then also takes states of non-neighbours, keeps every agent's newest state on a
 * SensingBoard, and is ready only once the board holds every agent's q_k (doc/distributed.md,
 * "Sensing").
 */
class LockstepAgent {
 public:
  /// What became of a received neighbour state.
  enum class Receipt { Accepted, Duplicate, UnknownSender, WrongDimension, NonFinite, ImpossibleStep };

  /**
   * @param board with `safety:`, the board to share with other agents of this process (one per
   * formation); nullptr: a board of its own. Ignored without `safety:`.
   * @throws InvalidInput if id is not an agent of the (validated) scenario, or the board is of
   * another size.
   */
  LockstepAgent(const Scenario& scenario, int id, StartMethod start = StartMethod::Variational,
                std::shared_ptr<SensingBoard> board = nullptr);
  /**
   * The same over a scenario and its formation (makeFormation(*scenario)) shared by the agents of
   * one process: n agents hold one copy, not n (doc/distributed.md, "Local delivery").
   * @throws InvalidInput as above, or if `formation` is not of the scenario's size.
   */
  LockstepAgent(std::shared_ptr<const Scenario> scenario, std::shared_ptr<const Formation> formation, int id,
                StartMethod start = StartMethod::Variational, std::shared_ptr<SensingBoard> board = nullptr);

  /// Offers neighbour `sender`'s state (with `safety:`, any other agent's) at step m (q_m, q_{m-1}); never changes the agent's own
  /// state, and keeps nothing unless the state is Accepted.
  Receipt receive(long sender, long step, const std::vector<double>& position,
                  const std::vector<double>& previousPosition);
  /// What became of a step-stamped command.
  enum class CommandReceipt { Accepted, Late, Invalid, CannotTurn };

  /**
   * A broadcast command for the intervals from `step` on (doc/maths.md §9): it replaces the
   * schedule (the scenario's `manoeuvre:` or earlier commands) from that step on. The update at
   * step k (q_k -> q_{k+1}) uses the commands of intervals k - 1 and k, so a command is Late
   * if step < step() and the agent has advanced since its start or its last resume() (a resumed
   * agent takes the commands of the steps before it until its first update); Invalid if validateCommand refuses it (`error` says why); CannotTurn
   * if it turns and this agent's motion parameters are not exact. Refused commands change nothing.
   * With the same commands at the same steps, the agents compute what ManoeuvreIntegrator
   * computes, bit for bit.
   */
  CommandReceipt receiveCommand(long step, const Command& command, std::string* error = nullptr);
  /// The commands this agent holds (empty without a manoeuvre).
  const CommandSchedule& commands() const;

  /// Every neighbour's q_k is known (and, with `safety:`, every agent's).
  bool ready() const;
  /// Neighbour j's q_k is known.
  bool holdsNeighbourStep(int j) const;
  /// The newest state received from neighbour j (with `safety:`, from any agent j) (for a
  /// restarted agent to recover from).
  /// @return false if none is held.
  bool neighbourState(int j, long& step, std::vector<double>& position, std::vector<double>& previousPosition) const;
  /// q_k -> q_{k+1}. Requires ready().
  void advance();
  /**
   * Resumes at `step` with q_step and q_{step-1} as held by a neighbour or the monitor (crash
   * recovery): the state is everything the update needs, so the run goes on bit for bit.
   * @throws InvalidInput on a negative step, a wrong size or a non-finite value.
   */
  void resume(long step, const std::vector<double>& position, const std::vector<double>& previousPosition);
  /// q_k and q_{k-1} are finite (false once the run has diverged).
  bool finite() const;
  /// Back to the state before the last advance() (to report a non-finite step without it).
  void undo();

  /// With `safety:`: the agents whose q_k the board lacks, ascending (at most `limit`); else empty.
  std::vector<int> missingSensed(std::size_t limit) const;
  /// The board (nullptr without `safety:`).
  const std::shared_ptr<SensingBoard>& board() const { return board_; }
  /// How many half-spaces bound the filtered step that produced q_k (0 without `safety:`, at
  /// step 0 and after a resume, which does not know it).
  int constraintsActive() const { return constraintsActive_; }
  /**
   * With `safety:`, also keeps r from the agents of other formations as last heard (doc/maths.md
   * §10, "Other formations"): those within reach join the filter's sensed agents after the
   * formation's own, each margin its last step (ForeignMargin::LastStep). Where none is within
   * reach the step is unchanged, bit for bit. nullptr: none (the default).
   */
  void avoid(std::shared_ptr<const ForeignAgents> foreign) { foreign_ = std::move(foreign); }
  /// Of the half-spaces constraintsActive() counts, those of other formations' agents: a step
  /// where this is > 0 depends on another formation's timing, so the run cannot equal simulate.
  int foreignConstraintsActive() const { return foreignConstraintsActive_; }

  int id() const { return id_; }
  long step() const { return step_; }
  double time() const { return static_cast<double>(step_) * coefficients_.timeStep; }
  /// scenario steps reached (never for steps = 0, unbounded).
  bool finished() const { return scenario_->steps > 0 && step_ >= scenario_->steps; }
  /// advance() ran since the start or the last resume().
  bool advancedSinceResume() const { return advanced_; }
  const std::vector<double>& position() const { return q_; }
  const std::vector<double>& previousPosition() const { return qPrev_; }
  const std::vector<int>& neighbourIds() const { return neighbourhood_.neighbourIds(); }
  const Scenario& scenario() const { return *scenario_; }

  static std::string describe(Receipt receipt);

 private:
  struct NeighbourState {
    long step = -1;
    std::vector<double> position;
    std::vector<double> previousPosition;
  };
  /// The forced update or start (doc/maths.md §9) from the held positions; d doubles.
  void manoeuvreStep(double* next);
  /// Neighbour's q_k if held, else nullptr.
  const double* neighbourPositionAtStep(const NeighbourState& s) const;
  bool isNeighbour(long j) const { return held(j) != nullptr; }
  /// Neighbour j's held state; nullptr if j is not a neighbour.
  const NeighbourState* held(long j) const;
  NeighbourState* held(long j) { return const_cast<NeighbourState*>(static_cast<const LockstepAgent*>(this)->held(j)); }
  /// Filters q_{k+1} (`next`) with the agents the board senses at k (doc/maths.md §10).
  void filter(double* next);
  /// Puts its own q_k on the board.
  void offerOwn();

  std::shared_ptr<const Scenario> scenario_;  // possibly shared with the process's other agents
  // The formation as this agent knows it: its start, neighbours, the checks of a neighbour's
  // state, grad_i V (scaled under a command) and its centroid offset.
  AgentNeighbourhood neighbourhood_;
  VariationalCoefficients coefficients_;
  StartMethod start_;
  int id_;
  int dimension_;
  long step_ = 0;
  bool advanced_ = false;  // advance() ran since the start or the last resume()
  std::vector<double> qPrev_, q_, qBeforePrev_;
  std::vector<NeighbourState> neighbours_;  // one per neighbour, in neighbourIds() order
  // (agent id, index in neighbours_), by id: a neighbour's state in O(log |N_i|), with memory
  // per agent that grows with its neighbours, not with the formation.
  std::vector<std::pair<int, int>> slots_;
  std::vector<double> spare_;  // d doubles: the next position is computed here, then rotated in
  // Set once the agent has a command (the scenario's manoeuvre, or a received one); until then
  // advance() runs today's update unchanged.
  std::unique_ptr<ManoeuvreModel> manoeuvre_;
  std::shared_ptr<SensingBoard> board_;  // with safety only
  std::vector<SensedAgent> sensed_;      // reused per step
  SafeStep safeStep_;
  int constraintsActive_ = 0, previousConstraintsActive_ = 0;
  std::shared_ptr<const ForeignAgents> foreign_;  // other formations' agents (avoid), or nullptr
  int foreignConstraintsActive_ = 0, previousForeignConstraintsActive_ = 0;
};

}  // namespace vf
