#pragma once

#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <ros/ros.h>

#include "variational_formation_msgs/AgentState.h"
#include "variational_formation_msgs/FormationCommands.h"
#include "variational_formation_msgs/RecallHistory.h"
#include "variational_formation_msgs/RecallState.h"
#include "variational_formation_msgs/RunProgress.h"
#include "variational_formation/ros/foreign_formations.hpp"
#include "variational_formation/ros/frame_broadcaster.hpp"
#include "variational_formation/ros/local_states.hpp"
#include "variational_formation_core/protocol/topic_audience.hpp"
#include "variational_formation/ros/periodic_call.hpp"
#include "variational_formation/ros/recalled.hpp"
#include "variational_formation/ros/reused_messages.hpp"
#include "variational_formation/ros/state_batch.hpp"
#include "variational_formation_core/agents/lockstep_agent.hpp"
#include "variational_formation_core/protocol/agent_protocol.hpp"

namespace vf {

using variational_formation_msgs::AgentState;
using variational_formation_msgs::AgentStatePtr;
using variational_formation_msgs::RecallHistory;
using variational_formation_msgs::RecallState;
using variational_formation_msgs::RunProgress;

/**
 * ROS I/O of one agent in lockstep mode (doc/distributed.md). Event-driven: every callback hands
 * its message to protocol::AgentProtocol and carries out the Ready it returns (publish, log, a
 * pacing timer, a wake-up from the board): the gates, histories and failures are the protocol's,
 * all maths is LockstepAgent's.
 *
 * On start it asks its neighbours and the monitor for the newest state of its own they hold, and
 * resumes from the highest step found (crash recovery; at step 0, or when nobody holds anything,
 * it starts from the scenario). It serves the same question for its neighbours (`~recall`), and
 * its states after the monitor's last completed step for a restarted monitor (`~history`), and
 * the neighbours' states it accepted after that step (`~history` with a neighbour's id).
 * It publishes its state at once (latched, step 0 included) and the tf world -> <ns>/agent_<id>;
 * it accepts a neighbour's state only from the node that owns it, and it computes step k only
 * once the monitor's latched `progress` allows k. When the monitor says the run is over it idles
 * until shut down (a respawning node that exited would only be restarted); its exit status is
 * then 0 if the run finished, 1 if it failed.
 *
 * With the scenario's `safety:` block it filters every step (doc/maths.md §10) and needs every
 * agent's state at each step (doc/distributed.md, "Sensing"): in an agent_manager from the board
 * the manager's agents share (SensingHub), elsewhere from every agent's state topic.
 *
 * In an agent_manager, its own agents hand their states to each other through the manager's
 * LocalExchange (doc/distributed.md, "Local delivery"), and an agent publishes on its topic only
 * while a subscriber outside the process is connected (TopicAudience), each new one getting the
 * newest state at once; it still subscribes to its local neighbours' topics, where it drops
 * states that others forge.
 *
 * Topics, services and private parameters (types, defaults, meaning): doc/ros_api.md, "agent
 * (lockstep mode)", the one list (test/doc/test_docs.py keeps it in step with the code).
 */
class AgentNode {
 public:
  /// What the holders (neighbours, then the monitor) answered about this agent's newest state.
  using Recovery = Recalled;

  /// Reads and checks the parameters and the scenario, advertises the state topic and the
  /// recall and history services (answered on nh's callback queue). Callbacks run on nh's
  /// queue (the global one for a node, the nodelet's own one in a manager), one at a time.
  /// @throws InvalidInput on a missing or bad parameter or scenario.
  AgentNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  ~AgentNode();
  /// The recall calls of crash recovery: blocks up to 2 s, touches nothing that callbacks change,
  /// so it may run on any thread.
  Recovery askHolders() const;
  /// Resumes from `recovery`, subscribes, publishes the first state and starts the timers. Call
  /// on nh's queue (or before it is served).
  void start(const Recovery& recovery);
  /// The node's main: start(askHolders()), then spins the global queue until shutdown.
  /// @return 0, or 1 if the monitor said the run failed.
  int run();

 private:
  using Protocol = protocol::AgentProtocol<AgentState::ConstPtr, RunProgress>;

  void onNeighbourState(int neighbour, const ros::MessageEvent<AgentState const>& event);
  /// Takes the neighbours' states that the manager's exchange holds from it (on this agent's queue).
  void listenLocally();
  /// The states in inbox_, oldest first.
  void readInbox();
  /// Advertises the state topic: latched, or with the exchange, gated by the audience.
  void advertiseState(ros::NodeHandle& nh);
  /// With a shared board: a Wake on this agent's queue once the board holds step k (src/ros/agent_sensing.cpp).
  void wakeWhenSensed();
  /// With `safety:` and `avoid` not none: `agent` also keeps r from other formations' agents.
  void avoidOtherFormations(const ros::NodeHandle& nh, const ros::NodeHandle& pnh, LockstepAgent& agent);
  /// Whose states it subscribes to: its neighbours, and with an own board every other agent.
  std::vector<int> sources() const;
  void onProgress(const ros::MessageEvent<RunProgress const>& event);
  /// The monitor's list of issued commands (src/ros/agent_commands.cpp).
  void onCommands(const ros::MessageEvent<variational_formation_msgs::FormationCommands const>& event);
  /// Does what the protocol said, in its order.
  void carryOut(const Protocol::Ready& ready);
  /// A Wake for the protocol in `wait` seconds, released by the process's Pacer (once per step).
  void paceFor(double wait);
  /// The state message of the agent's current step (the protocol's MakeState).
  AgentState::ConstPtr makeState(const LockstepAgent& agent, const std::string& failure) const;
  void publish(const AgentState::ConstPtr& state);
  void reportWaiting();
  void drop(const std::string& why);
  void resume(const Recovery& recovery);
  /// Protocol's Ready::recallAgain: askHolders() from a thread of its own, the answer then
  /// given to the protocol on this agent's queue (src/ros/agent_recovery.cpp).
  void recallAgain();
  /// Ends the wait for the monitor after a resume in an agent_manager: the progress held meanwhile
  /// goes to the protocol (src/ros/agent_recovery.cpp).
  void monitorConnected();
  /// Protocol's Ready::askNeighbourHistories: `~history` of each neighbour j in `ids` from j and
  /// j's neighbours, from a thread of its own; their states of j then go to the protocol on this
  /// agent's queue (src/ros/agent_recovery.cpp).
  void askNeighbourHistories(const std::vector<int>& ids);
  bool onRecall(RecallState::Request& request, RecallState::Response& response);
  bool onHistory(RecallHistory::Request& request, RecallHistory::Response& response);
  const LockstepAgent& agent() const { return protocol_->agent(); }

  ros::NodeHandle nh_;
  std::shared_ptr<const Formation> formation_;  // the process's one (sharedFormation): who neighbours whom
  std::shared_ptr<ForeignFormations> foreign_;  // with safety and avoid: other formations' agents
  std::unique_ptr<Protocol> protocol_;
  // Its own state messages (makeState): the oldest, once nothing else holds it (its step is out
  // of every history, queue and latch), is filled again for the next state. Held longer than 128
  // states (a stalled monitor), the oldest is left to its holders.
  mutable ReusedMessages<AgentState> made_{128};
  ros::Publisher statePub_;
  LocalStates::Exchange* exchange_ = nullptr;  // the manager's, if it hosts this agent
  std::unique_ptr<TopicAudience<AgentState::ConstPtr>> audience_;  // with exchange_: who else needs the topic
  // States of neighbours on this agent's thread, handed over by the exchange (AgentThreads::soon).
  std::vector<std::pair<int, AgentState::ConstPtr>> inbox_;
  bool inboxRead_ = false;  // a readInbox is due on the thread's lane
  Protocol::Ready ready_;   // readInbox's, reused (its buffers kept)
  std::vector<ros::Subscriber> subs_;
  std::map<int, std::string> owners_;         // full node names of sources(), by agent id
  std::vector<std::string> managers_;         // ~agent_manager: nodelet managers of agents
  ros::Subscriber progressSub_, commandSub_;
  ros::ServiceServer recallServer_, historyServer_;
  std::string monitor_;
  FrameBroadcaster tf_{nh_};  // after nh_
  long pacedStep_ = -1;  // the step whose release by the Pacer it waits for (-1: none)
  double realTimeFactor_ = 0.0;
  ros::WallTime lastReportAt_;
  long stepSeen_ = -1;          // the agent's step at the waiting line's last look
  ros::WallTime stepSeenAt_;    // when that look saw it move
  long dropped_ = 0;
  std::string name_, frame_, worldFrame_;
  bool sharedBoard_ = false;  // the manager's board (SensingHub), not one of its own
  long wakeStep_ = -1;        // the step a wake-up from the board is asked for
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);  // read by queued wake-ups
  // readInbox as AgentThreads::soon's task, handed over for every read (no allocation per call);
  // its node is null once the node is gone, for a read still on the lane.
  struct InboxReader : AgentThreads::Task {
    explicit InboxReader(AgentNode* n) : node(n) {}
    void run() override {
      if (node) node->readInbox();
    }
    AgentNode* node;
  };
  std::shared_ptr<InboxReader> inboxReader_ = std::make_shared<InboxReader>(this);
  // The waiting line (not a roscpp timer: one per agent of a manager is costly). Last, so that it
  // stops, and a call in progress ends, before any member it reads goes.
  PeriodicCall watch_;
  // Resumed in an agent_manager: no step until the monitor is connected to where this agent's
  // states go (the manager's batch, or its own topic), or kMonitorWait has passed. A state
  // published before that would reach no holder outside the process, and a second kill would
  // lose it for good (doc/distributed.md, "Crash recovery").
  bool awaitMonitor_ = false;
  ros::WallTime awaitSince_;
  bool progressHeld_ = false;
  ros::MessageEvent<RunProgress const> heldProgress_;  // the newest progress while it waits
};

}  // namespace vf
