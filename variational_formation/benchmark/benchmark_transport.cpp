// The ceiling the transport sets for a nodelet run (README, "Throughput"): the lockstep message
// pattern of `formation.launch nodelet:=true` with no maths and no protocol. N agents in this one
// process, a ring with chords (neighbours i±1, i±2), each publishes AgentState step k + 1 as soon
// as it holds its neighbours' step k; intra-process, as shared pointers, on one spinner thread.
// One more subscriber stands for the monitor: on every agent's topic (--collector topics, the
// pattern before batching) or on one batch topic that gets every state (--collector batch); in
// this process, or with --remote in a second process (forked before ROS starts), over TCP as the
// monitor gets them. Prints the steps/s from the first publication (remote: the first message
// collected) to the last state collected.
//
// --delivery local (the default) hands the states between the agents of the process as an
// agent_manager does (doc/distributed.md, "Local delivery"): through a LocalExchange, one queued
// call per state and listener, each agent's topic silent until a subscriber in another
// process connects (TopicAudience), so the in-process collector of `--collector topics`
// listens to the exchange too. --delivery roscpp publishes every state on its topic, as before:
// roscpp's publish finds the topic by a linear search through all of the process's publications,
// so its cost per agent-step grows with the agents (doc/benchmarks.md).
//
// usage: benchmark_transport [--agents N] [--steps S] [--collector topics|batch] [--remote]
//        [--delivery local|roscpp]
//        (needs a master; benchmark/transport_ceiling.sh starts one)
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

#include "variational_formation_msgs/AgentState.h"
#include "variational_formation_msgs/AgentStates.h"
#include "variational_formation_core/protocol/local_exchange.hpp"
#include "variational_formation_core/protocol/topic_audience.hpp"
#include "variational_formation/ros/pacer.hpp"

namespace {
using variational_formation_msgs::AgentState;
using variational_formation_msgs::AgentStates;

using Exchange = vf::LocalExchange<AgentState::ConstPtr>;

struct Agent {
  ros::Publisher pub;
  std::unique_ptr<vf::TopicAudience<AgentState::ConstPtr>> audience;  // --delivery local
  std::vector<int> neighbours;
  std::vector<long> heard;  // newest step held of each neighbour
  long step = 0;
};

struct Bench {
  int n = 100;
  long steps = 2000;
  bool batch = false;
  std::unique_ptr<Exchange> exchange;  // --delivery local: the agents' process hands states over itself
  std::vector<Agent> agents;
  std::vector<ros::Subscriber> subs;
  ros::Publisher batchPub;
  AgentStates::Ptr pending;
  long collected = 0;

  void publish(int i) {
    Agent& a = agents[static_cast<std::size_t>(i)];
    auto msg = boost::make_shared<AgentState>();
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
    if (batch) {
      pending->states.push_back(*msg);
      if (static_cast<int>(pending->states.size()) == n) {
        batchPub.publish(AgentStates::ConstPtr(pending));
        pending = boost::make_shared<AgentStates>();
      }
    }
  }
  void tryAdvance(int i) {
    Agent& a = agents[static_cast<std::size_t>(i)];
    while (a.step < steps) {
      for (long h : a.heard) {
        if (h < a.step) return;
      }
      ++a.step;
      publish(i);
    }
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
};
}  // namespace

int main(int argc, char** argv) {
  Bench b;
  bool remote = false, local = true;
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
    } else if (a == "--remote") {
      remote = true;
    } else if (a == "--delivery" && value) {
      const std::string d = argv[++k];
      if (d != "local" && d != "roscpp") {
        std::fprintf(stderr, "benchmark_transport: --delivery: local or roscpp, got '%s'\n", d.c_str());
        return 2;
      }
      local = d == "local";
    } else if (a == "--help" || a == "-h") {
      std::puts("usage: benchmark_transport [--agents N] [--steps S] [--collector topics|batch] [--remote] "
                "[--delivery local|roscpp]");
      return 0;
    } else {
      std::fprintf(stderr, "benchmark_transport: unknown or incomplete argument '%s' (see --help)\n", a.c_str());
      return 2;
    }
  }
  if (b.n < 5 || b.steps < 1) {
    std::fprintf(stderr, "benchmark_transport: needs --agents >= 5 and --steps >= 1\n");
    return 2;
  }
  const pid_t collector = remote ? fork() : 0;
  const bool collects = !remote || collector == 0;  // this process holds the collector
  const bool runsAgents = !remote || collector > 0;
  ros::init(argc, argv, collects && remote ? "benchmark_collector" : "benchmark_transport",
            ros::init_options::AnonymousName | ros::init_options::NoSigintHandler);
  ros::NodeHandle nh("bench");
  b.agents.resize(static_cast<std::size_t>(b.n));
  b.pending = boost::make_shared<AgentStates>();
  const long total = static_cast<long>(b.n) * b.steps;  // states after step 0
  auto start = std::chrono::steady_clock::now(), done = start;
  bool first = true;
  auto count = [&](long states) {
    if (first && remote) start = std::chrono::steady_clock::now();
    first = false;
    b.collected += states;
    if (b.collected >= total) {
      done = std::chrono::steady_clock::now();
      ros::shutdown();
    }
  };
  if (local && runsAgents) {
    std::vector<int> ids;
    for (int i = 0; i < b.n; ++i) ids.push_back(i);
    b.exchange = std::make_unique<Exchange>(ids);
  }
  for (int i = 0; i < b.n; ++i) {
    Agent& a = b.agents[static_cast<std::size_t>(i)];
    if (!b.exchange) {
      a.pub = nh.advertise<AgentState>("agent_" + std::to_string(i), 1000);
      continue;
    }
    a.audience = std::make_unique<vf::TopicAudience<AgentState::ConstPtr>>(ros::this_node::getName());
    vf::TopicAudience<AgentState::ConstPtr>* audience = a.audience.get();
    ros::AdvertiseOptions options = ros::AdvertiseOptions::create<AgentState>(
        "agent_" + std::to_string(i), 1000,
        [audience](const ros::SingleSubscriberPublisher& s) {
          if (const AgentState::ConstPtr newest = audience->connected(s.getSubscriberName())) s.publish(*newest);
        },
        ros::SubscriberStatusCallback(), ros::VoidConstPtr(), nullptr);
    options.latch = true;  // as an agent_manager's agents (TopicAudience)
    a.pub = nh.advertise(options);
  }
  if (b.batch) b.batchPub = nh.advertise<AgentStates>("states", 1000);
  for (int i = 0; i < b.n; ++i) {
    Agent& a = b.agents[static_cast<std::size_t>(i)];
    for (int d : {-2, -1, 1, 2}) a.neighbours.push_back((i + d + b.n) % b.n);
    a.heard.assign(a.neighbours.size(), 0);
    for (std::size_t k = 0; runsAgents && k < a.neighbours.size(); ++k) {
      if (b.exchange) {
        b.listen(a.neighbours[k], static_cast<std::uintptr_t>(i), [&b, i, k](const AgentState::ConstPtr& m) { b.onNeighbour(i, k, m); });
        continue;
      }
      b.subs.push_back(nh.subscribe<AgentState>("agent_" + std::to_string(a.neighbours[k]), 1000,
                                                [&b, i, k](const AgentState::ConstPtr& m) { b.onNeighbour(i, k, m); }));
    }
    if (collects && !b.batch && b.exchange) {  // the collector in the agents' process
      b.listen(i, static_cast<std::uintptr_t>(b.n + i), [&count](const AgentState::ConstPtr& m) { count(m->step > 0 ? 1 : 0); });
    } else if (collects && !b.batch) {
      b.subs.push_back(nh.subscribe<AgentState>("agent_" + std::to_string(i), 1000,
                                                [&count](const AgentState::ConstPtr& m) { count(m->step > 0 ? 1 : 0); }));
    }
  }
  if (collects && b.batch) {
    b.subs.push_back(nh.subscribe<AgentStates>("states", 1000, [&count](const AgentStates::ConstPtr& m) {
      long states = 0;
      for (const auto& s : m->states) states += s.step > 0 ? 1 : 0;
      count(states);
    }));
  }
  if (!runsAgents) {  // the remote collector: count until everything came
    ros::spin();
  } else {
    // Let every connection come up (the remote collector's too), then start: step 0 of every agent.
    ros::WallDuration(remote ? 3.0 : 1.0).sleep();
    for (int i = 0; i < 20 && ros::ok(); ++i) ros::spinOnce();
    start = std::chrono::steady_clock::now();
    for (int i = 0; i < b.n; ++i) b.publish(i);
    if (!remote) {
      ros::spin();
    } else {  // serve the collector until it exits
      int status = 0;
      while (waitpid(collector, &status, WNOHANG) == 0) ros::spinOnce();
      return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
    }
  }
  const double seconds = std::chrono::duration<double>(done - start).count();
  std::printf("benchmark_transport: %d agents, %ld steps, collector %s%s, %s delivery: %.3f s, %.0f steps/s\n", b.n,
              b.steps, b.batch ? "batch" : "topics", remote ? " (another process)" : " (this process)",
              local ? "local" : "roscpp", seconds, b.steps / seconds);
  return b.collected >= total ? 0 : 1;
}
