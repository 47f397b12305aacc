#pragma once

#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <visualization_msgs/MarkerArray.h>

#include "variational_formation/AgentState.h"
#include "variational_formation/FormationStatus.h"
#include "variational_formation/RecallHistory.h"
#include "variational_formation/RecallState.h"
#include "variational_formation/RunProgress.h"
#include "variational_formation/core/monitor.hpp"

namespace vf {

using variational_formation::AgentState;
using variational_formation::FormationStatus;
using variational_formation::RecallHistory;
using variational_formation::RecallState;
using variational_formation::RunProgress;

/**
 * The referee of a run (doc/distributed.md): collects every agent's states (only from the node
 * that owns each agent), publishes `status` and `markers` for each completed step, and the
 * latched `progress` that starts the agents once every participant is there and holds them at
 * most ~window steps ahead of what it and the recorder have completed. It says every few
 * seconds what a stalled run waits for, ends the run as failed when a participant dies, and
 * writes the outcome to ~result_file. Maths: FormationMonitor.
 *
 * Topics, services and private parameters: doc/ros_api.md, "monitor".
 *
 * Clock (~publish_clock, lockstep): it publishes /clock with the simulated time t_k of each
 * completed step, unless that is behind the ROS time it already has (another formation's monitor
 * ahead on the same master), so that with /use_sim_time tf lookups at now() and rviz follow the run.
 *
 * Timed mode (~mode timed, ~real_time_factor > 0; doc/robots.md): the agents do not wait for each
 * other, so there are no completed steps to wait for. Once every agent's first state is there it
 * starts the run, then measures the newest state of every agent on a wall-clock timer of period
 * h / rate (its own step count is the timer's) and reports the age of the oldest data it used
 * (`max_data_age`). The run ends after the scenario's steps of that timer, or when every agent
 * has reached them. The Noether predictions do not hold there: they are published as NaN.
 *
 * Recovery: it serves `~recall` (each agent's newest state, for a restarted agent), and when it
 * starts in the middle of a run it rebuilds the steps it had not completed from the agents'
 * `~history` and goes on from there.
 */
class MonitorNode {
 public:
  /// @throws InvalidInput on a missing or bad parameter or scenario.
  MonitorNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  /// Until the run ends (or shutdown). @return the exit status: 0 finished, 1 failed.
  int run();

 private:
  struct Participant {
    std::string node;            // full node name
    bool seen = false;           // has sent a valid message
    ros::WallTime goneSince;     // zero while alive
    std::string host;            // the node its messages came from: itself, or its nodelet manager
  };
  void recover();
  std::vector<RecallHistory::Response> fetchHistories(const std::vector<int>& agents);
  void addHistory(int agent, const RecallHistory::Response& held);
  void catchUpFromNeighbours(const std::vector<int>& agents);
  bool onRecall(RecallState::Request& request, RecallState::Response& response);
  bool onHistory(RecallHistory::Request& request, RecallHistory::Response& response);
  void onState(int agent, const ros::MessageEvent<AgentState const>& event);
  void onRecorderProgress(const ros::MessageEvent<RunProgress const>& event);
  void publishCompleted();
  void updateProgress();
  void watch();
  bool checkAlive(Participant& p, const std::string& what, double timeout);
  std::string waitingFor() const;
  void finish(uint8_t state, std::string reason);
  void writeResult(const std::string& result, const std::string& reason) const;
  // Timed mode.
  bool acceptTimed(int agent, const AgentState& msg, std::string& why);
  void tickTimed();
  void watchTimed();
  long completedStep() const { return monitor_->nextStep() - 1; }

  ros::NodeHandle nh_;
  std::unique_ptr<FormationMonitor> monitor_;
  std::vector<ros::Subscriber> subs_;
  ros::Subscriber recorderSub_;
  ros::Publisher statusPub_, markersPub_, progressPub_;
  /// ~publish_clock (lockstep): /clock follows the completed steps' simulated time, never backwards.
  bool publishClock_ = false;
  ros::Publisher clockPub_;
  ros::WallTimer watchTimer_;
  ros::ServiceServer recallServer_, historyServer_;
  /// Accepted states the recorder has not confirmed, per agent (at most a window each): an agent
  /// that dies again before the recorder got them no longer holds them.
  std::vector<std::deque<AgentState>> unrecordedStates_;
  std::vector<AgentState> newest_;          // each agent's newest state, for ~recall
  std::map<long, long> congruentSinceAt_;   // completed step -> first step of its congruent stretch
  std::vector<Participant> agents_;
  std::vector<std::string> managers_;  // ~agent_manager: nodelet managers of agents
  Participant recorder_;
  bool recording_ = false;
  long recordedStep_ = -1;
  bool recorderDone_ = false;
  std::vector<std::deque<Eigen::Vector3d>> trails_;
  int trailLength_ = 100;
  long markerEvery_ = 1;  // ~marker_every: markers of every k-th step (and the first and last)
  long window_ = 100;
  bool waitForViewer_ = false;
  double respawnTimeout_ = 0.0;
  std::string resultFile_;
  RunProgress progress_;
  long acceptUpTo_ = 0;
  /// Published status and markers the recorder has not confirmed (at most a window of them).
  std::deque<std::pair<FormationStatus, visualization_msgs::MarkerArray>> unrecorded_;  // states past this step cannot come yet (bounds the buffer)
  long dropped_ = 0;
  long reportedConvergence_ = -2;
  long convergedStep_ = -1;
  double finalError_ = 0.0;  // max distance error at the last completed step [m]
  ros::WallTime firstStepAt_, lastCompletedAt_, lastReportAt_, startedAt_;
  int exitStatus_ = -1;
  // Timed mode.
  bool timed_ = false;
  double rate_ = 0.0;
  std::vector<double> receivedAt_;  // wall time [s] of each agent's newest state
  ros::WallTimer tickTimer_;
  long tick_ = -1;
  double dataAge_ = 0.0;            // of the oldest state used by the newest status [s]
};

}  // namespace vf
