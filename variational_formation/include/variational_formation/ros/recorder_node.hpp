#pragma once

#include <memory>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include "variational_formation/ros/bag_writer.hpp"
#include "variational_formation/ros/raw_message.hpp"
#include "variational_formation/ros/state_batch.hpp"
#include "variational_formation_msgs/AgentState.h"
#include "variational_formation_msgs/FormationCommands.h"
#include "variational_formation_msgs/FormationStatus.h"
#include "variational_formation_msgs/RecallHistory.h"
#include "variational_formation_msgs/RunProgress.h"
#include "variational_formation_core/protocol/recorder_protocol.hpp"
#include "variational_formation_core/model/scenario.hpp"

namespace vf {

using variational_formation_msgs::AgentState;
using variational_formation_msgs::FormationStatus;
using variational_formation_msgs::RecallHistory;
using variational_formation_msgs::RunProgress;

/**
 * Records a run to a bag, losslessly (doc/distributed.md): every agent state (only from the node
 * that owns the agent), every status and marker array of the monitor, and /tf written from the
 * recorded states (the transforms the agents broadcast: /tf is not latched, so a recorder that
 * subscribed to it could miss the first step). It is a named participant: it reports on
 * `~progress` the last step of which it has written every agent state and the status, and the
 * monitor holds the agents back until it has. Bag time is the simulated time t_k, so
 * `rosbag play --clock` replays the run at the simulated pace.
 *
 * Size limits, like `rosbag record --split --size`: ~split_size (MB, default 256; 0 = one file)
 * starts a new file <bag>_1.bag, <bag>_2.bag, ... once the current one reaches it, and
 * ~max_size (MB, default 1024; 0 = no limit) ends the recording, with a warning, once all files
 * together reach it; the run goes on and the recorder keeps counting steps, so it never holds
 * the agents back afterwards.
 *
 * What to write when, what to report and when to catch up is protocol::RecorderProtocol's; the
 * node moves messages to it and writes what it says. Steps are written whole and in order
 * (states with their transforms, status, markers), once all of step k has arrived and after
 * step k - 1, so the bag is in time order however late a state came. The bag holds each (agent, step) state, each status and each step's markers once: a copy that
 * arrives again (from a history fetched while the topic was still delivering it, or from an
 * agent that republishes after a restart) is not written, and a repeated state that differs
 * from the written one, bit for bit, fails the run (RecordLedger).
 *
 * Topics, services and private parameters: doc/ros_api.md, "recorder".
 */
class RecorderNode {
 public:
  RecorderNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  /// Until the monitor ends the run (or shutdown). @return the exit status.
  int run();

  /// The monitor's marker arrays, stored as they came (RawMessage).
  using RawMarkers = RawMessage<visualization_msgs::MarkerArray>;
  /// The stamp of the first marker (that of the step), read from the serialised array; an empty
  /// (or cut short) array has none: TIME_MIN.
  static ros::Time markersStamp(const RawMarkers& msg);

 private:
  using Protocol = protocol::RecorderProtocol<AgentState::ConstPtr, FormationStatus::ConstPtr, RawMarkers::ConstPtr>;
  template <typename M>
  void write(BagWriter::Topic& topic, const M& msg, const ros::Time& stamp);
  void onState(int agent, const ros::MessageEvent<AgentState const>& event);
  /// A manager's batch of its agents' states (doc/distributed.md, "Batches").
  void onBatch(std::size_t source, const ros::MessageEvent<variational_formation_msgs::AgentStates const>& event);
  /// A state from the owner's topic: to the protocol.
  void record(int agent, const AgentState::ConstPtr& msg);
  /// Does what the protocol said, in its order.
  void carryOut(const Protocol::Ready& ready);
  /// Writes one whole step (and the commands that apply from it) to the bag.
  void writeStep(const Protocol::Write& w);
  /// The recorder's progress as a message (stamped with the simulated time of its completed step).
  RunProgress progressMessage(const protocol::Progress& p) const;
  /// The monitor publishes the markers of every marker_every-th step and of the last one.
  bool needsMarkers(long step) const;
  /// Asks the protocol whether to catch up, and fetches the histories it names.
  void catchUp();
  void onStatus(const ros::MessageEvent<FormationStatus const>& event);
  void onMarkers(const ros::MessageEvent<RawMarkers const>& event);
  void onMonitorProgress(const ros::MessageEvent<RunProgress const>& event);
  void close(const std::string& how);
  /// Ends the recording and tells the monitor, which ends the run as failed, naming the reason.
  void fail(const std::string& reason);
  void openPart();
  void enforceLimits();
  // Live commands (src/ros/recorder_commands.cpp).
  void setUpCommands(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  void onCommands(const ros::MessageEvent<variational_formation_msgs::FormationCommands const>& event);
  /// Writes the first `count` listed commands, as the list so far, at t_step: just before the
  /// step's states.
  void writeListedCommands(std::size_t count, long step);
  /// The whole schedule the agents apply, as a `simulate --commands` file (~commands_file).
  void writeCommandsFile() const;

  ros::NodeHandle nh_;
  BagWriter bag_;
  BagWriter::Compression compression_ = BagWriter::Compression::Lz4;  // ~compression
  std::string path_, monitor_;
  BagWriter::Topic statusTopic_, markersTopic_, commandsTopic_, tfTopic_{"/tf"};
  std::vector<BagWriter::Topic> stateTopics_;  // by agent
  std::vector<std::string> frameIds_;          // by agent
  tf2_msgs::TFMessage tf_;                     // a step's /tf, reused (writeStep)
  std::vector<ros::Subscriber> subs_;
  ros::Publisher progressPub_;
  long lastStep_ = 0;  // the scenario's steps (0: unbounded)
  double timeStep_ = 0.0;
  std::vector<std::string> owners_;
  std::vector<std::string> managers_;  // ~agent_manager: nodelet managers of agents
  std::vector<BatchSource> batches_;    // those of them whose agents come batched
  /// Steps not yet written (at most protocol::recorderLead of them) and the states held; every
  /// stream of the steps it handed out is in the bag (or past its size limit).
  std::unique_ptr<Protocol> protocol_;
  long markerEvery_ = 1;
  long written_ = 0, dropped_ = 0;
  bool open_ = false;
  ros::WallTimer catchUpTimer_;
  bool limited_ = false;  // the size limit ended the recording
  double splitBytes_ = 0.0, maxBytes_ = 0.0, closedBytes_ = 0.0;
  int part_ = 0;
  int exitStatus_ = -1;
  Scenario scenario_;
  std::string commandsFile_;  // ~commands_file ("" : none)
  variational_formation_msgs::FormationCommands commands_;  // the monitor's newest list
};

}  // namespace vf
