#pragma once

#include <deque>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <dynamic_reconfigure/server.h>
#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <std_msgs/Float64.h>
#include <visualization_msgs/MarkerArray.h>

#include "variational_formation_msgs/AgentState.h"
#include "variational_formation/FormationConfig.h"
#include "variational_formation_msgs/FormationStatus.h"
#include "variational_formation_msgs/RecallHistory.h"
#include "variational_formation_msgs/RecallState.h"
#include "variational_formation_msgs/RunProgress.h"
#include "variational_formation_core/agents/formation_monitor.hpp"
#include "variational_formation_core/robots/robot_shape_watch.hpp"
#include "variational_formation_core/agents/run_verdict.hpp"
#include "variational_formation_core/safety/safety_watch.hpp"
#include "variational_formation_core/safety/foreign_watch.hpp"
#include "variational_formation/ros/foreign_formations.hpp"
#include "variational_formation_core/protocol/command_desk.hpp"
#include "variational_formation_core/protocol/lockstep_referee.hpp"
#include "variational_formation_core/protocol/timed_referee.hpp"
#include "variational_formation_core/protocol/referee_ready.hpp"
#include "variational_formation/ros/frame_gate.hpp"
#include "variational_formation/ros/frames.hpp"
#include "variational_formation/ros/goal_server.hpp"
#include "variational_formation/ros/service_call.hpp"
#include "variational_formation/ros/state_batch.hpp"
#include "variational_formation/ros/trails.hpp"

namespace vf {

using variational_formation_msgs::AgentState;
using variational_formation_msgs::FormationStatus;
using variational_formation_msgs::RecallHistory;
using variational_formation_msgs::RecallState;
using variational_formation_msgs::RunProgress;

/**
 * The monitor's wiring that both modes share (doc/distributed.md, doc/ros_api.md "monitor"): the
 * common parameters, the `status`, `markers` and latched `progress` publishers, /clock, the
 * participants and whether they are alive, the result file and the end of the run. What a state
 * means, when the run starts, flows and ends is the mode's referee (core/protocol):
 * LockstepMonitor or TimedMonitor. Built by makeMonitor from ~mode.
 */
class MonitorNode {
 public:
  virtual ~MonitorNode() = default;
  /// Until the run ends (or shutdown). @return the exit status: 0 finished, 1 failed.
  int run();

 protected:
  /// A subscriber of the markers other than the recorder (rviz) is connected (~wait_for_viewer).
  bool viewer() const { return viewers_ > 0; }
  struct Participant {
    std::string node;         // full node name
    bool seen = false;        // has sent a valid message
    ros::WallTime goneSince;  // zero while alive
    std::string host;         // the node its messages came from: itself, or its nodelet manager
  };
  using Published = std::pair<FormationStatus, visualization_msgs::MarkerArray>;

  /// Reads and checks the common parameters and the scenario (@throws InvalidInput), opens the
  /// result file, advertises and subscribes every agent's state (delivered from run() on).
  /// `timed` selects which of ~recorder and ~publish_clock apply.
  MonitorNode(ros::NodeHandle& nh, ros::NodeHandle& pnh, bool timed);
  /// The line every monitor starts with.
  void announce(const std::string& recorder) const;

  // What the mode decides.
  /// A state of `agent` that passed the identity checks, from `publisher`. @return accepted.
  /// @param msg held by pointer (into the batch it came in, which it keeps alive), not copied.
  virtual bool offer(int agent, const AgentState::ConstPtr& msg, const std::string& publisher) = 0;
  /// After one or more accepted states (a state, or a manager's batch).
  virtual void afterAccepted() {}
  virtual void begin() = 0;  ///< before spinning (a restarted lockstep monitor recovers here)
  virtual void watch() = 0;  ///< every 0.5 s
  virtual std::string waitingFor() const = 0;
  virtual long completedStep() const = 0;
  virtual const FormationMonitor& measure() const = 0;
  /// Hands the applied schedule to the mode's referee: the steps it measures from now on are
  /// measured under it (FormationMonitor::setSchedule).
  virtual void measureUnder(const CommandSchedule& schedule) = 0;
  /// The stamp of what the monitor says about `step`: its simulated time in lockstep (replay and
  /// /clock need it), ROS time now in timed mode (robots and tf consumers live in it).
  virtual ros::Time stampOf(long step) const = 0;
  /// The commanded motion the agents apply (the markers follow it), or nullptr without one.
  const CommandSchedule* commandSchedule() const {
    return desk_->schedule().empty() ? nullptr : &desk_->schedule();
  }
  /// A good command is pending in desk_: the mode issues it (lockstep at the allowed step, timed
  /// at once).
  virtual void commandOffered() = 0;
  /// A failure the monitor found, or a blocked formation: the mode's referee decides the end, and
  /// the mode carries out its Ready.
  virtual void report(const protocol::Failure& failure) = 0;
  virtual void report(const protocol::Blocked& blocked) = 0;

  // Live commands (src/ros/monitor_commands.cpp, doc/protocol.md "Commands").
  void setUpCommands(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  void onVelocityCommand(const ros::MessageEvent<geometry_msgs::Twist const>& event);
  void onScaleCommand(const ros::MessageEvent<std_msgs::Float64 const>& event);
  /// A command from a sender not in ~commanders is refused (empty: anyone may command).
  bool commanderAllowed(const std::string& sender, const char* topic);
  /// A WARN line for an accepted command that was saturated or turns fast (`note` from the desk).
  void warnCommand(const char* topic, const std::string& sender, const std::string& note) const;
  void refuseCommand(const char* topic, const std::string& sender, const std::string& why);
  /// Issues what is pending at `step`, keeps the list on the parameter server, publishes it;
  /// @return the number of issued commands, for the progress.
  long issueCommands(long step);
  /// How many commands have been issued (the result file, the progress).
  long commandsIssued() const { return static_cast<long>(desk_->issued().size()); }
  /// A new run forgets an earlier run's commands; a resumed one goes on from the kept list.
  void resumeCommands(bool resumed);
  /// The issued list on `command`, stamped as the mode stamps what it says (stampOf).
  void publishCommands();

  // Goals (src/ros/monitor_goals.cpp): move_to and move_base_simple/goal, steered through desk_.
  void setUpGoals(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  /// A published step for the goal: `constrained` a safety constraint bound at it.
  void steerGoal(const FormationSnapshot& s, bool constrained, const ros::Time& stamp);
  std::unique_ptr<GoalServer> goals_;
  long goalCommandsAt_ = -1;  ///< where the Ready being carried out issues commands (-1: nowhere)

  // The formation's kappa (src/ros/monitor_parameters.cpp, doc/ros_api.md "monitor"): a
  // dynamic_reconfigure server in the formation's namespace, whose latched parameter_updates the
  // timed agents follow. Lockstep (`timed` false) refuses any change.
  void setUpParameters(ros::NodeHandle& nh, bool timed);
  void onReconfigure(variational_formation::FormationConfig& config, uint32_t level);

  /// /clock at the newest completed step's time, if not sent yet (and not behind another formation's).
  void publishClock();
  /// Publishes one completed step's status and markers (and /clock), stamped `stamp`; tracks the
  /// congruent stretch for the result; reports a formation it finds blocked (report(Blocked)).
  /// @return what was published, for the recorder gate.
  Published publishSnapshot(const FormationSnapshot& s, const ros::Time& stamp, double dataAge, bool noetherHolds);
  // The safety filter as the monitor sees it (src/ros/monitor_safety.cpp, doc/ros_api.md
  // "monitor"): min_separation and constraints_active in every status, the closest approach and
  // filter_active_steps in the result file, and a blocked formation ends the run.
  /// ~blocked_after, and the watch (a scenario with `safety:` only).
  void setUpSafety(ros::NodeHandle& pnh, bool timed);
  /// An accepted state's constraints_active.
  void noteSafety(int agent, const AgentState& msg);
  /// Fills the status's min_separation, constraints_active and closest foreign pair. @return the formation is blocked
  /// (it has just become so: the run ends).
  bool watchSafety(const FormationSnapshot& s, FormationStatus& status);
  /// The result file's safety lines (empty without a safety block).
  std::string safetyResultLines() const;
  /// "blocked: agents 2, 4" once the safety filter has blocked the formation, else empty
  /// (shapeVerdict then says "not converged (blocked: …)").
  std::string blockedBy() const;

  /// Publishes `progress` (its header stamped with the completed step's simulated time).
  void publishProgress(const RunProgress& progress);
  /// Agent `agent` was heard (from `publisher`: its node or its manager).
  void heard(int agent, const std::string& publisher);
  void drop(int agent, const std::string& why);
  /// @return false once `p` has been gone longer than `timeout` [s] (reported as a Failure).
  bool checkAlive(Participant& p, const std::string& what, double timeout);
  void reportWaiting(const std::string& line);
  /// Carries out a Ready's end (RefereeReady::finish): the referee's end `end`, once (finished may
  /// turn into failed when the scenario requires convergence).
  void finish(const protocol::Progress& end);
  bool ended() const { return exitStatus_ >= 0; }
  static std::string agentList(const std::vector<int>& ids) {
    return protocol::LockstepReferee<AgentState::ConstPtr, Published>::agentList(ids);
  }

  ros::NodeHandle nh_;
  std::string path_, worldFrame_;
  Scenario scenario_;
  std::string recorderParam_;  // ~recorder, relative
  bool recording_ = false;     // a recorder takes part (lockstep)
  long window_ = 100;
  bool waitForViewer_ = false;
  int viewers_ = 0;  // subscribers of the markers other than the recorder (~wait_for_viewer)
  double respawnTimeout_ = 0.0;
  std::vector<std::string> managers_;  // ~agent_manager: nodelet managers of agents
  std::vector<Participant> agents_;
  ros::Publisher statusPub_, markersPub_, progressPub_;
  RunProgress progress_;
  long dropped_ = 0;
  ros::WallTime firstStepAt_, lastCompletedAt_, lastReportAt_, startedAt_;
  long reportedConvergence_ = -2;  // the congruent stretch already announced (-2: none)
  long congruentSince_ = -1;       // first step of the congruent stretch (either hand) at the newest step (-1: none)
  long commandsRefused_ = 0;  // live commands refused, for the result file
  std::unique_ptr<protocol::CommandDesk> desk_;
  ros::NodeHandle pnh_;
  ros::Subscriber velocityCommandSub_, scaleCommandSub_;
  ros::Publisher commandPub_;
  std::vector<std::string> commanders_;  // full node names; empty: anyone
  std::unique_ptr<dynamic_reconfigure::Server<variational_formation::FormationConfig>> reconfigure_;
  double kappa_ = 0.0;       // the formation's kappa [1/s]
  bool kappaFixed_ = false;  // lockstep: the scenario's, for good
  std::string kappaName_;    // its parameter, resolved (/formation/kappa)

  // The run's shape (src/ros/monitor_shape.cpp): the newest step's findings and the verdict
  // that `simulate` gives too (shapeOutcome), for the result file and the last line.
  void noteShape(const FormationSnapshot& s);
  /// The agents' verdict; with ~measure_robots the run's is the worse or later of it and the
  /// robots' (robotModeOutcome).
  ShapeOutcome agentsVerdict() const;
  ShapeOutcome shapeVerdict() const;

  // The robots of a robot-mode run (src/ros/monitor_robots.cpp, doc/robots.md "Converged means
  // the robots"), with ~measure_robots: robot_<i>/odom, averaged (core RobotShapeWatch), the
  // robots' errors in every status, their verdict in the result file and the last line.
  /// ~measure_robots, ~kinematics, ~hand_offset, ~robots_window; subscribes to the odometry.
  void setUpRobots(ros::NodeHandle& nh, ros::NodeHandle& pnh, bool timed);
  void onOdometry(int id, const nav_msgs::Odometry& msg);
  /// Measures the robots at the step of `s` and fills the status's robots_ fields.
  void watchRobots(const FormationSnapshot& s, FormationStatus& status);
  /// A WARN line (every 5 s at most) naming the robots whose odometry has not come or stopped.
  void reportRobotsMissing();
  /// The result file's robots_ lines (empty without ~measure_robots).
  std::string robotsResultLines() const;
  std::unique_ptr<RobotShapeWatch> robots_;

 private:
  void writeResult(const std::string& result, const std::string& reason) const;
  void onAgentTopic(int agent, const ros::MessageEvent<AgentState const>& event);
  void onBatch(std::size_t source, const ros::MessageEvent<variational_formation_msgs::AgentStates const>& event);
  /// A state from a sender allowed to speak for `agent`: ends the run on its failure, else offers it.
  bool admit(int agent, const AgentState::ConstPtr& msg, const std::string& publisher);

  std::vector<ros::Subscriber> subs_;
  std::vector<BatchSource> batches_;  // managers whose agents come batched (doc/distributed.md, "Batches")
  ros::Publisher clockPub_;
  bool publishClock_ = false;  // ~publish_clock (lockstep): /clock follows the completed steps, never backwards
  // /clock goes out at the first and the last step and at most every kClockPeriod of wall time
  // between (100 Hz, as `rosbag play` publishes it), with the newest completed step's time; the
  // watch timer sends one held back when the run pauses. Every step's /clock went to every node
  // of the run (they all subscribe under /use_sim_time): at 100 agents it cost a quarter of the
  // throughput (doc/benchmarks.md).
  static constexpr double kClockPeriod = 0.01;  // [s] of wall time
  ros::Time clockDue_, clockSent_;  // the newest completed step's time; the last one sent
  ros::WallTime clockAt_;           // when the last one was sent
  ros::WallTimer watchTimer_;
  Trails trails_{1, 2};  // replaced once the scenario is read
  int trailLength_ = 100;
  long markerEvery_ = 1;
  long allMarkersEvery_ = 1;   // steps between arrays with the trails and the ghost (allMarkersEvery)
  long allMarkersStep_ = -1;   // the step of the last such array published
  std::string resultFile_;
  double finalError_ = 0.0;  // max distance error at the last completed step [m]
  ShapeFindings lastShape_;  // at the newest completed step (noteShape)
  Positions lastPositions_;
  double lastScale_ = 1.0;
  int exitStatus_ = -1;
  std::unique_ptr<SafetyWatch> safety_;  // a scenario with `safety:` only
  std::shared_ptr<ForeignFormations> foreign_;  // with safety and avoid: the other formations' agents
  std::unique_ptr<ForeignWatch> foreignWatch_;  // over foreign_
  std::vector<ros::Subscriber> odomSubs_;  // ~measure_robots: robot_<i>/odom
  long badOdometry_ = 0;                   // odometry messages refused (not finite, not a rotation)
  std::unique_ptr<FrameGate> odomFrames_;  // ~measure_robots: odometry in another frame than worldFrame_
  long reportedRobots_ = -2;               // the robots' in-shape stretch already announced (-2: none)
  ros::WallTime robotsReportedAt_;         // the last line about missing robots
};

/**
 * Lockstep mode: the referee of an exact run (protocol::LockstepReferee). Collects every agent's
 * states, publishes each completed step, starts the agents by identity and holds them at most
 * ~window steps ahead of what it and the recorder completed; catches up missing states from the
 * agents' histories and their neighbours'; serves `~recall` and `~history`; a restarted monitor
 * rebuilds the steps it had not completed from the agents' histories and goes on.
 */
class LockstepMonitor : public MonitorNode {
 public:
  LockstepMonitor(ros::NodeHandle& nh, ros::NodeHandle& pnh);

 private:
  using Referee = protocol::LockstepReferee<AgentState::ConstPtr, Published>;
  bool offer(int agent, const AgentState::ConstPtr& msg, const std::string& publisher) override;
  void afterAccepted() override { updateProgress(); }
  void begin() override;
  void watch() override;
  std::string waitingFor() const override { return referee_->waitingFor(recorder_.node); }
  long completedStep() const override { return referee_->completedStep(); }
  const FormationMonitor& measure() const override { return referee_->monitor(); }
  void measureUnder(const CommandSchedule& schedule) override { referee_->setSchedule(schedule); }
  ros::Time stampOf(long step) const override { return ros::Time(std::max(0L, step) * scenario_.timeStep); }
  void commandOffered() override { updateProgress(); }  // issued at the allowed step, then counted
  void report(const protocol::Failure& failure) override { carryOut(referee_->step(failure)); }
  void report(const protocol::Blocked& blocked) override { carryOut(referee_->step(blocked)); }
  void onRecorderProgress(const ros::MessageEvent<RunProgress const>& event);
  bool onRecall(RecallState::Request& request, RecallState::Response& response);
  bool onHistory(RecallHistory::Request& request, RecallHistory::Response& response);
  /// The referee's Update: each completed step, then the progress.
  void updateProgress() { carryOut(referee_->step(Referee::Update{viewer()})); }
  /// Does what `r` says, in its order (RefereeReady).
  void carryOut(const Referee::Ready& r);
  /// The states agents `ids` hold of themselves (`~history`), in order of `ids`.
  std::vector<RecallHistory::Response> fetchHistories(const std::vector<int>& ids);
  void catchUpFromNeighbours(const std::vector<int>& ids);

  std::unique_ptr<Referee> referee_;
  Participant recorder_;
  ros::Subscriber recorderSub_;
  ros::ServiceServer recallServer_, historyServer_;
};

/**
 * Timed mode (doc/robots.md): the agents do not wait for each other. Once every agent's first
 * state is there it starts the run, then measures the newest state of every agent on a
 * wall-clock timer of period h / rate (protocol::TimedReferee) and reports the age of the oldest
 * data it used. The run ends after the scenario's steps of that timer, or when every agent has
 * reached them. The Noether predictions do not hold there: they are published as NaN.
 */
class TimedMonitor : public MonitorNode {
 public:
  TimedMonitor(ros::NodeHandle& nh, ros::NodeHandle& pnh);

 private:
  bool offer(int agent, const AgentState::ConstPtr& msg, const std::string& publisher) override;
  void begin() override;
  void watch() override;
  std::string waitingFor() const override;
  long completedStep() const override { return referee_->completedStep(); }
  const FormationMonitor& measure() const override { return referee_->monitor(); }
  void measureUnder(const CommandSchedule& schedule) override { referee_->setSchedule(schedule); }
  ros::Time stampOf(long) const override { return ros::Time::now(); }
  /// Timed agents apply the newest command at their next tick: issued at once.
  void commandOffered() override;
  void report(const protocol::Failure& failure) override { carryOut(referee_->step(failure)); }
  void report(const protocol::Blocked& blocked) override { carryOut(referee_->step(blocked)); }
  /// The stamp of the newest issued command (-1: none).
  long lastCommandStep() const { return desk_->issued().empty() ? -1 : desk_->issued().back().first; }
  /// Does what `r` says, in its order (RefereeReady).
  void carryOut(const protocol::RefereeReady& r);

  std::unique_ptr<protocol::TimedReferee<AgentState>> referee_;
  double rate_ = 0.0;
  ros::WallTimer tickTimer_;
};

/// The monitor of ~mode (lockstep or timed). @throws InvalidInput on a bad parameter or scenario.
std::unique_ptr<MonitorNode> makeMonitor(ros::NodeHandle& nh, ros::NodeHandle& pnh);

}  // namespace vf
