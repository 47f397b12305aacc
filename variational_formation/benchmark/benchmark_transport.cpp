// The ceiling the transport sets for a nodelet run (README, "Throughput"): the lockstep message
// pattern of `formation.launch nodelet:=true` with no maths and no protocol. N agents in this one
// process, a ring with chords (neighbours i±1, i±2), each publishes AgentState step k + 1 as soon
// as it holds its neighbours' step k, as shared pointers. One more subscriber stands for the
// monitor: on every agent's topic (--collector topics, the pattern before batching) or on one
// batch topic that gets every state (--collector batch), read as the monitor reads it
// (subscribeToBatches); in this process, or with --remote in a second process (forked before ROS
// starts), over TCP as the monitor gets them. Prints the steps/s from the first publication
// (remote: the first message collected) to the last state collected.
//
// --delivery manager (the default) is an agent_manager's transport as it is (doc/distributed.md,
// "Local delivery" and "Threads"), with the package's own classes: the agents' callbacks on the
// one thread of AgentThreads, each state handed through the LocalExchange into its neighbours'
// inboxes and read right after (AgentThreads::soon), each agent's topic silent until a subscriber
// in another process connects (TopicAudience), the batches made by StateBatch, and every agent's
// messages reused once nothing holds them (as AgentNode::makeState). --delivery local is the
// exchange with one queued call per state and listener on roscpp's global queue, spun by the main
// thread (this benchmark's default until issue 34's last round). --delivery roscpp publishes every
// state on its topic: roscpp's publish finds the topic by a linear search through all of the
// process's publications, so its cost per agent-step grows with the agents (doc/benchmarks.md).
//
// usage: benchmark_transport [--agents N] [--steps S] [--collector topics|batch] [--remote]
//        [--delivery manager|local|roscpp]
//        (needs a master; benchmark/transport_ceiling.sh starts one)
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <ros/callback_queue.h>
#include <ros/ros.h>

#include <std_msgs/Int64.h>

#include "variational_formation_msgs/AgentState.h"
#include "variational_formation_msgs/AgentStates.h"
#include "variational_formation_core/protocol/local_exchange.hpp"
#include "variational_formation_core/protocol/topic_audience.hpp"
#include "variational_formation/ros/pacer.hpp"
#include "variational_formation/ros/reused_messages.hpp"
#include "variational_formation/ros/state_batch.hpp"

namespace {
using variational_formation_msgs::AgentState;
using variational_formation_msgs::AgentStates;

using Exchange = vf::LocalExchange<AgentState::ConstPtr>;

/// A call as AgentThreads' task, made once per agent.
struct Reader : vf::AgentThreads::Task {
  explicit Reader(std::function<void()> c) : call(std::move(c)) {}
  void run() override { call(); }
  std::function<void()> call;
};

struct Agent {
  ros::Publisher pub;
  std::unique_ptr<vf::TopicAudience<AgentState::ConstPtr>> audience;  // --delivery local
  std::vector<int> neighbours;
  std::vector<long> heard;  // newest step held of each neighbour
  long step = 0;
  // --delivery manager: neighbours' states handed over on the agents' thread, and this agent's
  // messages, reused once nothing else holds them.
  std::vector<std::pair<std::size_t, AgentState::ConstPtr>> inbox;
  bool inboxRead = false;
  std::shared_ptr<vf::AgentThreads::Task> reader;  // readInbox on the lane, as AgentNode's
  vf::ReusedMessages<AgentState> made{16};
  long allowed = 0;  // the flow window's end: this agent computes step k only while k <= allowed
};

struct Bench {
  int n = 100;
  long steps = 2000;
  bool batch = false;
  bool manager = false;                 // --delivery manager
  ros::CallbackQueue* queue = nullptr;  // --delivery manager: the agents' queue (AgentThreads)
  std::unique_ptr<Exchange> exchange;  // --delivery local: the agents' process hands states over itself
  std::vector<Agent> agents;
  std::vector<ros::Subscriber> subs;
  ros::Publisher batchPub;
  AgentStates::Ptr pending;
  long collected = 0;
  // The flow window, as the monitor's ~window: an agent computes step k only while k <= its
  // allowed, the collector's completed step + window, sent on bench/progress every quarter window
  // to each agent's own subscription (as each agent's RunProgress).
  long window = 100;
  long announced = 0;  // the collector's last completed step sent
  ros::Publisher progressPub;

  void publish(int i) {
    Agent& a = agents[static_cast<std::size_t>(i)];
    const AgentState::Ptr msg = manager ? a.made.next() : boost::make_shared<AgentState>();
    msg->id = static_cast<uint32_t>(i);
    msg->step = a.step;
    msg->position = {1.0 * i, 0.5 * a.step};
    msg->previous_position = {1.0 * i, 0.5 * (a.step - 1)};
    const AgentState::ConstPtr state(msg);
    if (!exchange) {
      a.pub.publish(state);
    } else {
      exchange->deliver(i, state);
      if (a.audience->published(state)) a.pub.publish(state);
    }
    if (manager) {
      if (batch) vf::StateBatch::local()->add(state);
    } else if (batch) {
      pending->states.push_back(*msg);
      if (static_cast<int>(pending->states.size()) == n) {
        batchPub.publish(AgentStates::ConstPtr(pending));
        pending = boost::make_shared<AgentStates>();
      }
    }
  }
  void tryAdvance(int i) {
    Agent& a = agents[static_cast<std::size_t>(i)];
    while (a.step < steps && a.step < a.allowed) {
      for (long h : a.heard) {
        if (h < a.step) return;
      }
      ++a.step;
      publish(i);
    }
  }
  /// The collector's completed step, to agent i: it may go `window` steps past it.
  void onProgress(int i, long completed) {
    Agent& a = agents[static_cast<std::size_t>(i)];
    if (completed + window <= a.allowed) return;
    a.allowed = completed + window;
    tryAdvance(i);
  }
  void onNeighbour(int i, std::size_t k, const AgentState::ConstPtr& msg) {
    Agent& a = agents[static_cast<std::size_t>(i)];
    a.heard[k] = std::max(a.heard[k], static_cast<long>(msg->step));
    tryAdvance(i);
  }
  /// --delivery local: f(state) on the global queue (the one spinner) for each state of `source`.
  template <class F>
  void listen(int source, std::uintptr_t listener, F f) {
    exchange->listen(source, listener, [f](int, const AgentState::ConstPtr& m) {
      vf::queueCall(ros::getGlobalCallbackQueue(), [f, m] { f(m); }, 0);
    });
  }
  /// --delivery manager: agent i hears its k-th neighbour as AgentNode::listenLocally does: on
  /// the agents' thread into its inbox, read right after; from any other thread, a call on its queue.
  void listenAsManager(int i, std::size_t k) {
    Agent& own = agents[static_cast<std::size_t>(i)];
    if (!own.reader) own.reader = std::make_shared<Reader>([this, i] { readInbox(i); });
    exchange->listen(agents[static_cast<std::size_t>(i)].neighbours[k], static_cast<std::uintptr_t>(i),
                     [this, i, k](int, const AgentState::ConstPtr& m) {
                       Agent& a = agents[static_cast<std::size_t>(i)];
                       if (vf::AgentThreads::serves(queue)) {
                         a.inbox.emplace_back(k, m);
                         if (!a.inboxRead) {
                           a.inboxRead = true;
                           vf::AgentThreads::soon(a.reader);
                         }
                         return;
                       }
                       vf::queueCall(queue, [this, i, k, m] { onNeighbour(i, k, m); }, 0);
                     });
  }
  void readInbox(int i) {
    Agent& a = agents[static_cast<std::size_t>(i)];
    a.inboxRead = false;
    for (std::size_t k = 0; k < a.inbox.size(); ++k) {  // by index, as AgentNode::readInbox
      const std::pair<std::size_t, AgentState::ConstPtr> arrived = std::move(a.inbox[k]);
      onNeighbour(i, arrived.first, arrived.second);
    }
    a.inbox.clear();
  }
};
}  // namespace

int main(int argc, char** argv) {
  Bench b;
  bool remote = false, local = true;
  std::string delivery = "manager";
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    const bool value = k + 1 < argc;
    if (a == "--agents" && value) {
      b.n = std::atoi(argv[++k]);
    } else if (a == "--steps" && value) {
      b.steps = std::atol(argv[++k]);
    } else if (a == "--collector" && value) {
      const std::string c = argv[++k];
      if (c != "topics" && c != "batch") {
        std::fprintf(stderr, "benchmark_transport: --collector: topics or batch, got '%s'\n", c.c_str());
        return 2;
      }
      b.batch = c == "batch";
    } else if (a == "--window" && value) {
      b.window = std::atol(argv[++k]);
    } else if (a == "--remote") {
      remote = true;
    } else if (a == "--delivery" && value) {
      delivery = argv[++k];
      if (delivery != "manager" && delivery != "local" && delivery != "roscpp") {
        std::fprintf(stderr, "benchmark_transport: --delivery: manager, local or roscpp, got '%s'\n", delivery.c_str());
        return 2;
      }
    } else if (a == "--help" || a == "-h") {
      std::puts("usage: benchmark_transport [--agents N] [--steps S] [--collector topics|batch] [--remote] "
                "[--delivery manager|local|roscpp] [--window W]");
      return 0;
    } else {
      std::fprintf(stderr, "benchmark_transport: unknown or incomplete argument '%s' (see --help)\n", a.c_str());
      return 2;
    }
  }
  if (b.n < 5 || b.steps < 1 || b.window < 1) {
    std::fprintf(stderr, "benchmark_transport: needs --agents >= 5, --steps >= 1 and --window >= 1\n");
    return 2;
  }
  local = delivery != "roscpp";
  b.manager = delivery == "manager";
  const pid_t collector = remote ? fork() : 0;
  const bool collects = !remote || collector == 0;  // this process holds the collector
  const bool runsAgents = !remote || collector > 0;
  ros::init(argc, argv, collects && remote ? "benchmark_collector" : "benchmark_transport",
            ros::init_options::AnonymousName | ros::init_options::NoSigintHandler);
  ros::NodeHandle nh("bench");
  b.agents.resize(static_cast<std::size_t>(b.n));
  // The window keeps the agents within window + a quarter of it of the collector: every queue
  // holds twice the window, as the monitor's own, so none drops a state.
  const auto depth = static_cast<uint32_t>(std::min<long>(2 * b.window + 10, 1000000L));
  b.pending = boost::make_shared<AgentStates>();
  const long total = static_cast<long>(b.n) * b.steps;  // states after step 0
  auto start = std::chrono::steady_clock::now(), done = start;
  bool first = true;
  auto count = [&](long states) {
    if (first && remote) start = std::chrono::steady_clock::now();
    first = false;
    b.collected += states;
    const long completed = b.collected / b.n;  // steps come whole and in order (the agents wait on each other)
    if (completed >= b.announced + std::max(1L, b.window / 4)) {
      b.announced = completed;
      std_msgs::Int64 progress;
      progress.data = completed;
      b.progressPub.publish(progress);
    }
    if (b.collected >= total) {
      done = std::chrono::steady_clock::now();
      ros::shutdown();
    }
  };
  if (local && runsAgents) {
    std::vector<int> ids;
    for (int i = 0; i < b.n; ++i) ids.push_back(i);
    b.exchange = std::make_unique<Exchange>(ids);
    if (b.manager) {
      vf::AgentThreads::start(1, static_cast<std::size_t>(b.n));
      b.queue = vf::AgentThreads::local()->nextQueue();
      if (b.batch) vf::StateBatch::start(nh, ids);  // on bench/states, as a manager's ~states
    }
  }
  for (int i = 0; i < b.n; ++i) {
    Agent& a = b.agents[static_cast<std::size_t>(i)];
    if (!b.exchange) {
      a.pub = nh.advertise<AgentState>("agent_" + std::to_string(i), depth);
      continue;
    }
    a.audience = std::make_unique<vf::TopicAudience<AgentState::ConstPtr>>(ros::this_node::getName());
    vf::TopicAudience<AgentState::ConstPtr>* audience = a.audience.get();
    ros::AdvertiseOptions options = ros::AdvertiseOptions::create<AgentState>(
        "agent_" + std::to_string(i), depth,
        [audience](const ros::SingleSubscriberPublisher& s) {
          if (const AgentState::ConstPtr newest = audience->connected(s.getSubscriberName())) s.publish(*newest);
        },
        ros::SubscriberStatusCallback(), ros::VoidConstPtr(), nullptr);
    options.latch = true;  // as an agent_manager's agents (TopicAudience)
    a.pub = nh.advertise(options);
  }
  if (b.batch && !b.manager && runsAgents) b.batchPub = nh.advertise<AgentStates>("states", depth);
  for (int i = 0; i < b.n; ++i) {
    Agent& a = b.agents[static_cast<std::size_t>(i)];
    for (int d : {-2, -1, 1, 2}) a.neighbours.push_back((i + d + b.n) % b.n);
    a.heard.assign(a.neighbours.size(), 0);
    for (std::size_t k = 0; runsAgents && k < a.neighbours.size(); ++k) {
      if (b.manager) {
        b.listenAsManager(i, k);
        continue;
      }
      if (b.exchange) {
        b.listen(a.neighbours[k], static_cast<std::uintptr_t>(i), [&b, i, k](const AgentState::ConstPtr& m) { b.onNeighbour(i, k, m); });
        continue;
      }
      b.subs.push_back(nh.subscribe<AgentState>("agent_" + std::to_string(a.neighbours[k]), depth,
                                                [&b, i, k](const AgentState::ConstPtr& m) { b.onNeighbour(i, k, m); }));
    }
    if (collects && !b.batch && b.exchange) {  // the collector in the agents' process
      b.listen(i, static_cast<std::uintptr_t>(b.n + i), [&count](const AgentState::ConstPtr& m) { count(m->step > 0 ? 1 : 0); });
    } else if (collects && !b.batch) {
      b.subs.push_back(nh.subscribe<AgentState>("agent_" + std::to_string(i), depth,
                                                [&count](const AgentState::ConstPtr& m) { count(m->step > 0 ? 1 : 0); }));
    }
  }
  if (collects && b.batch) {
    b.subs.push_back(vf::subscribeToBatches(nh, "states", depth, [&count](const ros::MessageEvent<AgentStates const>& e) {
      long states = 0;
      for (const auto& s : e.getConstMessage()->states) states += s.step > 0 ? 1 : 0;
      count(states);
    }));
  }
  if (collects) b.progressPub = nh.advertise<std_msgs::Int64>("progress", 100);
  for (int i = 0; runsAgents && i < b.n; ++i) {  // on the agents' queue, one each, as their RunProgress
    b.agents[static_cast<std::size_t>(i)].allowed = b.window;
    ros::SubscribeOptions options = ros::SubscribeOptions::create<std_msgs::Int64>(
        "progress", 100, [&b, i](const std_msgs::Int64::ConstPtr& m) { b.onProgress(i, m->data); }, ros::VoidConstPtr(),
        b.manager ? b.queue : nullptr);
    options.transport_hints = ros::TransportHints().tcpNoDelay();
    b.subs.push_back(nh.subscribe(options));
  }
  if (!runsAgents) {  // the remote collector: count until everything came
    ros::spin();
  } else {
    // Let every connection come up (the remote collector's too), then start: step 0 of every agent.
    ros::WallDuration(remote ? 3.0 : 1.0).sleep();
    for (int i = 0; i < 20 && ros::ok(); ++i) ros::spinOnce();
    start = std::chrono::steady_clock::now();
    if (b.manager) {  // on the agents' thread, where every agent's callbacks run
      vf::queueCall(b.queue, [&b] { for (int i = 0; i < b.n; ++i) b.publish(i); }, 0);
    } else {
      for (int i = 0; i < b.n; ++i) b.publish(i);
    }
    int status = 0;
    if (!remote) {
      ros::spin();
    } else if (b.manager) {  // serve the collector until it exits; the main thread waits, as a manager's
      while (waitpid(collector, &status, WNOHANG) == 0) ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.01));
    } else {  // the main thread is the agents' one: it spins
      while (waitpid(collector, &status, WNOHANG) == 0) ros::spinOnce();
    }
    b.subs.clear();            // before the queue they call on goes
    vf::AgentThreads::stop();  // before the batch and the exchange they use
    vf::StateBatch::stop();
    if (remote) return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
  }
  const double seconds = std::chrono::duration<double>(done - start).count();
  std::printf("benchmark_transport: %d agents, %ld steps, collector %s%s, %s delivery: %.3f s, %.0f steps/s\n", b.n,
              b.steps, b.batch ? "batch" : "topics", remote ? " (another process)" : " (this process)",
              delivery.c_str(), seconds, b.steps / seconds);
  return b.collected >= total ? 0 : 1;
}
