// The agents' own share of a lockstep agent-step (doc/benchmarks.md, "Issue 34: the agent's own
// step, without a transport"): N agents on a ring with chords (make_scenario --shape ring), each
// the shipped AgentProtocol around its LockstepAgent, as an agent_manager holds them, with no
// ROS transport at all. A state goes straight into its neighbours' inboxes, read as
// AgentThreads' lane reads them (the agent last handed a state reads first). The state messages
// are variational_formation_msgs AgentState, reused once nothing holds them (ReusedMessages, as
// AgentNode::makeState). Progress goes to every agent each quarter window, with the allowed step
// a window ahead of the completed one (as the monitor's), and trims the histories. What the
// transport adds (the hand-over between agents, the batches, the monitor's process) is
// benchmark_transport's ceiling; the two together bound how close a lockstep run can come to it.
//
// usage: benchmark_protocol [--agents N] [--steps S] [--window W]
// Prints the steps per second and the µs per agent-step, from the first step to the last.
#include <chrono>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "variational_formation_core/agents/lockstep_agent.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation_core/protocol/agent_protocol.hpp"
#include "variational_formation/ros/reused_messages.hpp"
#include "variational_formation/tools/make_scenario_cli.hpp"
#include "variational_formation_msgs/AgentState.h"
#include "variational_formation_msgs/RunProgress.h"

namespace {

using variational_formation_msgs::AgentState;
using StatePtr = AgentState::ConstPtr;
using Protocol = vf::protocol::AgentProtocol<StatePtr, variational_formation_msgs::RunProgress>;

/// One agent: its protocol, its own messages for reuse, and its inbox (as AgentNode's).
struct Agent {
  std::unique_ptr<Protocol> protocol;
  vf::ReusedMessages<AgentState> made{128};  // as AgentNode's
  std::vector<StatePtr> inbox;  // read oldest first
  bool inboxRead = false;       // a read is on the lane
  Protocol::Ready ready;        // reused, as AgentNode's inbox reads
};

StatePtr makeState(vf::ReusedMessages<AgentState>& made, const vf::LockstepAgent& a, const std::string& failure) {
  const AgentState::Ptr state = made.next();
  AgentState& msg = *state;
  msg.header.stamp.fromSec(a.time());
  msg.header.frame_id = "world";
  msg.id = static_cast<uint32_t>(a.id());
  msg.step = a.step();
  msg.time = a.time();
  msg.position = a.position();
  msg.previous_position = a.previousPosition();
  msg.constraints_active = static_cast<uint32_t>(a.constraintsActive());
  msg.failure = failure;
  return state;
}

bool readLong(const char* text, long& value) {
  try {
    std::size_t used = 0;
    value = std::stol(text, &used);
    return used == std::string(text).size();
  } catch (const std::exception&) {
    return false;
  }
}

int run(long n, long steps, long window);

}  // namespace

int main(int argc, char** argv) {
  long n = 200, steps = 20000, window = 100;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    long* target = a == "--agents" ? &n : a == "--steps" ? &steps : a == "--window" ? &window : nullptr;
    if (a == "--help" || a == "-h") {
      std::puts("usage: benchmark_protocol [--agents N] [--steps S] [--window W]");
      return 0;
    }
    if (!target || k + 1 >= argc) {
      std::fprintf(stderr, "benchmark_protocol: unknown or incomplete argument '%s' (see --help)\n", a.c_str());
      return 2;
    }
    if (!readLong(argv[k + 1], *target)) {
      std::fprintf(stderr, "benchmark_protocol: %s: expects a whole number, got '%s'\n", a.c_str(), argv[k + 1]);
      return 2;
    }
    ++k;
  }
  if (n < 5 || n > 100000 || steps < 1 || steps > 100000000 || window < 4 || window > 1000000) {
    std::fprintf(stderr, "benchmark_protocol: needs --agents in [5, 100000], --steps in [1, 1e8] and --window in [4, 1e6]\n");
    return 2;
  }
  try {
    return run(n, steps, window);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "benchmark_protocol: %s\n", e.what());
    return 1;
  }
}

namespace {

int run(long n, long steps, long window) {
  std::ostringstream yaml, err;
  const std::string agents = std::to_string(n), count = std::to_string(steps);
  const char* args[] = {"make_scenario", "--shape", "ring", "--agents", agents.c_str(), "--perturb", "0.05",
                        "--seed", "1", "--steps", count.c_str(), "--name", "ring"};
  if (vf::runMakeScenarioCli(static_cast<int>(sizeof(args) / sizeof(args[0])), args, yaml, err) != 0) {
    std::fprintf(stderr, "benchmark_protocol: make_scenario: %s", err.str().c_str());
    return 1;
  }
  const auto scenario = std::make_shared<const vf::Scenario>(vf::parseScenario(yaml.str(), "ring"));
  const auto formation = std::make_shared<const vf::Formation>(vf::makeFormation(*scenario));

  std::vector<Agent> all(static_cast<std::size_t>(n));
  for (long i = 0; i < n; ++i) {
    vf::ReusedMessages<AgentState>& made = all[static_cast<std::size_t>(i)].made;
    all[static_cast<std::size_t>(i)].protocol = std::make_unique<Protocol>(
        vf::LockstepAgent(scenario, formation, static_cast<int>(i), vf::StartMethod::Variational, nullptr),
        [&made](const vf::LockstepAgent& a, const std::string& failure) { return makeState(made, a, failure); });
  }
  // Agents with an inbox to read, newest last (read newest first, as AgentThreads' lane).
  std::vector<long> lane;
  std::vector<long> published(static_cast<std::size_t>(steps) + 2, 0);  // agents past each step
  long completed = -1, told = -1;
  const auto handOut = [&](long from, const Protocol::Ready& ready) {
    for (const StatePtr& s : ready.publish) {
      for (int j : all[static_cast<std::size_t>(from)].protocol->agent().neighbourIds()) {
        Agent& to = all[static_cast<std::size_t>(j)];
        to.inbox.push_back(s);
        if (!to.inboxRead) {
          to.inboxRead = true;
          lane.push_back(j);
        }
      }
      ++published[static_cast<std::size_t>(s->step)];
    }
    if (!ready.failed.empty() || !ready.dropped.empty()) {
      std::fprintf(stderr, "benchmark_protocol: agent %ld: %s%s\n", from, ready.failed.c_str(), ready.dropped.c_str());
      std::exit(1);
    }
  };
  const auto progress = [&]() {
    while (completed < steps && published[static_cast<std::size_t>(completed + 1)] == n) ++completed;
    if (told >= 0 && completed < told + window / 4 && completed < steps) return;
    told = completed;
    Protocol::ProgressArrived p;
    p.progress.progress.state = completed >= steps ? vf::protocol::Progress::State::Finished
                                                   : vf::protocol::Progress::State::Running;
    p.progress.progress.completedStep = completed;
    p.progress.progress.allowedStep = std::min(steps, completed + window);
    p.message.completed_step = completed;
    p.message.allowed_step = p.progress.progress.allowedStep;
    for (long i = 0; i < n; ++i) handOut(i, all[static_cast<std::size_t>(i)].protocol->step(p));
  };
  for (long i = 0; i < n; ++i) handOut(i, all[static_cast<std::size_t>(i)].protocol->start());
  const auto begin = std::chrono::steady_clock::now();
  while (completed < steps) {
    const long toldBefore = told;
    progress();
    if (lane.empty()) {
      if (told == toldBefore) {  // nothing to read and no new progress: it cannot go on
        std::fprintf(stderr, "benchmark_protocol: stalled at step %ld\n", completed);
        return 1;
      }
      continue;
    }
    const long next = lane.back();
    lane.pop_back();
    Agent& a = all[static_cast<std::size_t>(next)];
    a.inboxRead = false;
    for (std::size_t k = 0; k < a.inbox.size(); ++k) {
      const StatePtr state = std::move(a.inbox[k]);
      a.protocol->step(Protocol::StateArrived{static_cast<int>(state->id), state}, a.ready);
      handOut(next, a.ready);
    }
    a.inbox.clear();
    a.ready.clear();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  const double agentSteps = static_cast<double>(n) * static_cast<double>(steps);
  std::printf("benchmark_protocol: %ld agents, %ld steps, window %ld: %.3f s, %.0f steps/s, %.3f us per agent-step\n",
              n, steps, window, seconds, static_cast<double>(steps) / seconds, 1e6 * seconds / agentSteps);
  return 0;
}

}  // namespace
