#pragma once

#include <condition_variable>
#include <deque>
#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <ros/callback_queue.h>
#include <ros/ros.h>

#include "variational_formation_msgs/AgentState.h"
#include "variational_formation_msgs/AgentStates.h"

namespace vf {

/**
 * An agent manager's batch of its agents' states (doc/distributed.md, "Batches"): the agents
 * loaded in this process add each state they publish, and it goes out on the manager's `~states`
 * as one AgentStates once every agent of ~agents has added one, or within 5 ms of the first state
 * it holds. The monitor and the recorder then take one message and one wake-up per step from a
 * manager instead of one per agent. One per process, started by agent_manager before it loads
 * its agents; agents in any other process have none. Thread-safe: the manager's workers add.
 */
class StateBatch {
 public:
  /// Starts this process's batch for agents `ids`, on `pnh`'s `states` (the manager's private handle).
  static void start(ros::NodeHandle& pnh, const std::vector<int>& ids);
  /// This process's batch; nullptr if it has none.
  static StateBatch* local();

  /// Ends this process's batch (before ROS shuts down).
  static void stop();
  ~StateBatch();

  /// A state its agent just published; states of agents not in ~agents are left out.
  void add(const variational_formation_msgs::AgentState::ConstPtr& state);
  /// ~agents: the agents this manager batches.
  const std::set<int>& ids() const { return ids_; }
  /**
   * Whether subscriber `node` (a full node name) is connected to the batches now. If it is not,
   * `call` goes onto `queue` once it connects (once). Every batch published after that reaches
   * it: a resumed agent waits for the monitor this way (doc/distributed.md, "Crash recovery").
   */
  bool connectedOrLater(const std::string& node, ros::CallbackQueueInterface* queue, std::function<void()> call);

 private:
  StateBatch(ros::NodeHandle& pnh, const std::vector<int>& ids);
  /// Every 5 ms until stopped, on a thread of its own: a roscpp timer would cost every other timer
  /// of the process a search through all of them each time it fires (TimerManager::findTimer).
  void flushEvery5ms();
  void flush();
  /// The pending batch, cut to the states added, and a new pending one (a spent batch no one
  /// holds any more, or a new one). Under mutex_.
  variational_formation_msgs::AgentStatesPtr takePending();
  /// Publishes `batch`, then keeps it among the spent ones.
  void publish(const variational_formation_msgs::AgentStatesPtr& batch);
  /// A subscriber that connects gets each agent's newest state at once, as the latched
  /// agent_<i>/state topics give it (a monitor or recorder started late misses nothing).
  void onConnect(const ros::SingleSubscriberPublisher& subscriber);
  void onDisconnect(const ros::SingleSubscriberPublisher& subscriber);

  std::set<int> ids_;
  std::mutex mutex_;
  variational_formation_msgs::AgentStatesPtr pending_;
  std::size_t filled_ = 0;  // states added to pending_ (a reused batch holds old ones after them)
  std::deque<variational_formation_msgs::AgentStatesPtr> spent_;  // published, oldest first
  std::vector<char> batched_;  // by agent id: in ids_ (a look-up per state, not a tree search)
  std::vector<variational_formation_msgs::AgentState::ConstPtr> newest_;  // by agent id; guarded by mutex_
  std::multiset<std::string> subscribers_;  // connected subscribers' node names; guarded by mutex_
  struct Waiter {
    std::string node;
    ros::CallbackQueueInterface* queue;
    std::function<void()> call;
  };
  std::vector<Waiter> waiters_;  // connectedOrLater's; guarded by mutex_
  ros::Publisher pub_;
  bool stopping_ = false;  // guarded by mutex_
  std::condition_variable stop_;
  std::thread flusher_;
};

/**
 * The callback threads of an agent manager's own agents (doc/distributed.md, "Threads"): the
 * manager's A agents, in load order, go to T queues in consecutive blocks (agent k to queue
 * k T / A; agents loaded later, beyond A, to k mod T), each queue served by a thread of its own.
 * Formations are numbered along their shape, so most neighbours share a thread and hand their
 * states over through the inbox; a state that crosses passes with one hand-over between threads,
 * where nodelet's queue manager needs two (its manager thread, then a worker). (Queue k mod T put
 * a ring's next neighbours on the other thread: 2 of every agent's 4 states crossed, at 100
 * agents a third of the manager's time in the queues' locks, wake-ups and allocations.) One agent's callbacks stay on one
 * thread, one at a time, as in a node. One per process, started by agent_manager; agents loaded
 * in any other manager keep nodelet's queues.
 */
class AgentThreads {
 public:
  /// Starts `threads` (>= 1) queues and threads for this process, for `agents` agents to load.
  static void start(int threads, std::size_t agents);
  /// Destroys this process's threads and queues (halting them first).
  static void stop();
  /// Joins the threads and disables the queues: no agent callback runs afterwards, and a callback
  /// added later is ignored (the queues stay, for agents that are still being unloaded).
  void halt();
  /// This process's, or nullptr.
  static AgentThreads* local();
  /// The queue of the next agent loaded.
  ros::CallbackQueue* nextQueue();
  /// Whether the calling thread is the one that serves `queue`.
  static bool serves(const ros::CallbackQueueInterface* queue);
  /// Work for soon(), kept by its caller and handed over as often as it likes: held by a shared
  /// pointer, it costs no allocation per call (a std::function holding one would).
  struct Task {
    virtual ~Task() = default;
    virtual void run() = 0;
  };
  /**
   * Runs `task->run()` on the calling thread (one of these threads) after the callback that adds
   * it, the newest added first, ahead of the queue's later callbacks but interleaved with them (64
   * at a time): a state handed from one agent to a neighbour on the same thread is read while it
   * is still in the cache (doc/distributed.md, "Local delivery"). Only from one of these threads.
   */
  static void soon(std::shared_ptr<Task> task);
  ~AgentThreads();

 private:
  AgentThreads(int threads, std::size_t agents);

  std::vector<std::unique_ptr<ros::CallbackQueue>> queues_;
  std::vector<std::thread> threads_;
  std::size_t agents_ = 0;  // agents to load, in blocks
  std::size_t next_ = 0;    // guarded by mutex_
  std::mutex mutex_;
  std::atomic<bool> stopping_{false};
};

/// Agents `ids` whose states come batched from `manager` (its full name).
struct BatchSource {
  std::string manager;
  std::set<int> ids;
};

/**
 * The managers among `managers` (full names) that batch their agents' states: each agent_manager
 * publishes its ~agents parameter, and only it batches. An agent listed by two managers is left
 * to its own topic. @param agents the formation's size: ids beyond it are ignored.
 */
std::vector<BatchSource> batchSources(const ros::NodeHandle& nh, const std::vector<std::string>& managers, int agents);

/// A manager's batches (`topic`, TCP_NODELAY), read into messages that come back once nothing
/// holds them: the states' vectors keep their memory, and a step's batch costs no allocation
/// per state (they were a tenth of a 200-agent monitor's time). Callbacks on `nh`'s queue.
ros::Subscriber subscribeToBatches(
    ros::NodeHandle& nh, const std::string& topic, uint32_t depth,
    const std::function<void(const ros::MessageEvent<variational_formation_msgs::AgentStates const>&)>& callback);

/// States that came by value (a `~history` answer), each as a shared message, as the monitor and
/// the recorder hold the states that come by topic or in batches.
std::vector<variational_formation_msgs::AgentState::ConstPtr> sharedStates(
    const std::vector<variational_formation_msgs::AgentState>& states);

/// The agent ids in ~agents text ("0 1 2"). @throws InvalidInput naming `parameter`.
std::vector<int> parseAgentIds(const std::string& list, const std::string& parameter);

}  // namespace vf
