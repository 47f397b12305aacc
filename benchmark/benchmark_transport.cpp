// The ceiling the transport sets for a nodelet run (README, "Throughput"): the lockstep message
// pattern of `formation.launch nodelet:=true` with no maths and no protocol. N agents in this one
// process, a ring with chords (neighbours i±1, i±2), each publishes AgentState step k + 1 as soon
// as it holds its neighbours' step k; intra-process, as shared pointers, on one spinner thread.
// One more subscriber stands for the monitor: on every agent's topic (--collector topics, the
// pattern before batching) or on one batch topic that gets every state (--collector batch).
// Prints the steps/s from the first publication to the last state collected.
//
// usage: benchmark_transport [--agents N] [--steps S] [--collector topics|batch]   (needs a master;
//        benchmark/transport_ceiling.sh starts one)
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <ros/ros.h>

#include "variational_formation/AgentState.h"
#include "variational_formation/AgentStates.h"

namespace {
using variational_formation::AgentState;
using variational_formation::AgentStates;

struct Agent {
  ros::Publisher pub;
  std::vector<int> neighbours;
  std::vector<long> heard;  // newest step held of each neighbour
  long step = 0;
};

struct Bench {
  int n = 100;
  long steps = 2000;
  bool batch = false;
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
    a.pub.publish(AgentState::ConstPtr(msg));
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
};
}  // namespace

int main(int argc, char** argv) {
  Bench b;
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
    } else if (a == "--help" || a == "-h") {
      std::puts("usage: benchmark_transport [--agents N] [--steps S] [--collector topics|batch]");
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
  ros::init(argc, argv, "benchmark_transport", ros::init_options::AnonymousName);
  ros::NodeHandle nh("bench");
  b.agents.resize(static_cast<std::size_t>(b.n));
  b.pending = boost::make_shared<AgentStates>();
  const long total = static_cast<long>(b.n) * b.steps;  // states after step 0
  auto done = std::chrono::steady_clock::now();
  auto count = [&](long states) {
    b.collected += states;
    if (b.collected >= total) {
      done = std::chrono::steady_clock::now();
      ros::shutdown();
    }
  };
  for (int i = 0; i < b.n; ++i) {
    b.agents[static_cast<std::size_t>(i)].pub = nh.advertise<AgentState>("agent_" + std::to_string(i), 1000);
  }
  if (b.batch) b.batchPub = nh.advertise<AgentStates>("states", 1000);
  for (int i = 0; i < b.n; ++i) {
    Agent& a = b.agents[static_cast<std::size_t>(i)];
    for (int d : {-2, -1, 1, 2}) a.neighbours.push_back((i + d + b.n) % b.n);
    a.heard.assign(a.neighbours.size(), 0);
    for (std::size_t k = 0; k < a.neighbours.size(); ++k) {
      b.subs.push_back(nh.subscribe<AgentState>("agent_" + std::to_string(a.neighbours[k]), 1000,
                                                [&b, i, k](const AgentState::ConstPtr& m) { b.onNeighbour(i, k, m); }));
    }
    if (!b.batch) {
      b.subs.push_back(nh.subscribe<AgentState>("agent_" + std::to_string(i), 1000,
                                                [&count](const AgentState::ConstPtr& m) { count(m->step > 0 ? 1 : 0); }));
    }
  }
  if (b.batch) {
    b.subs.push_back(nh.subscribe<AgentStates>("states", 1000, [&count](const AgentStates::ConstPtr& m) {
      long states = 0;
      for (const auto& s : m->states) states += s.step > 0 ? 1 : 0;
      count(states);
    }));
  }
  // Let every connection come up, then start: every agent publishes step 0.
  ros::WallDuration(1.0).sleep();
  for (int i = 0; i < 20 && ros::ok(); ++i) ros::spinOnce();
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < b.n; ++i) b.publish(i);
  ros::spin();
  const double seconds = std::chrono::duration<double>(done - start).count();
  std::printf("benchmark_transport: %d agents, %ld steps, collector %s: %.3f s, %.0f steps/s\n", b.n, b.steps,
              b.batch ? "batch" : "topics", seconds, b.steps / seconds);
  return b.collected >= total ? 0 : 1;
}
