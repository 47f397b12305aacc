#pragma once
// Lockstep agents without transport, shared by test_lockstep and test_lockstep_manoeuvre: states
// delivered one at a time in a random order, every step checked against the centralised run.

#include <gtest/gtest.h>

#include <functional>
#include <random>
#include <string>
#include <vector>

#include "variational_formation_core/agents/lockstep_agent.hpp"

namespace vf {
namespace test {

/// A state in flight: q_k and q_{k-1} of `sender` at `step`.
struct Message {
  int sender;
  long step;
  std::vector<double> q, qPrev;
};

/**
 * Runs `agents` until every one has finished. Each turn delivers one state in flight, picked by
 * `rng` (so states of one sender may overtake each other, and an overtaken one is refused as
 * "going back": a loss that the newer state, which carries q_{m-1}, makes good), to every agent,
 * which then advances while it is ready and broadcasts each new state. `onTurn(a)` runs after
 * each delivery and after each step of agent a (commands that are due). Every q_k is compared
 * with expected[k] bit for bit; `checked` counts the agent steps compared.
 */
inline void runInRandomOrder(std::vector<LockstepAgent>& agents, const std::vector<Positions>& expected,
                             std::mt19937& rng, const std::string& name, long* checked,
                             const std::function<void(LockstepAgent&)>& onTurn = {}) {
  std::vector<Message> inFlight;
  for (const auto& a : agents) inFlight.push_back({a.id(), a.step(), a.position(), a.previousPosition()});
  *checked = 0;
  while (true) {
    bool allDone = true;
    for (const auto& a : agents) allDone = allDone && a.finished();
    if (allDone) break;
    ASSERT_FALSE(inFlight.empty()) << "deadlock";
    std::uniform_int_distribution<std::size_t> pick(0, inFlight.size() - 1);
    const std::size_t m = pick(rng);
    const Message msg = inFlight[m];
    inFlight.erase(inFlight.begin() + static_cast<long>(m));
    for (auto& a : agents) {
      a.receive(msg.sender, msg.step, msg.q, msg.qPrev);
      if (onTurn) onTurn(a);
      while (!a.finished() && a.ready()) {
        a.advance();
        for (Eigen::Index c = 0; c < expected.front().rows(); ++c) {
          ASSERT_EQ(a.position()[static_cast<std::size_t>(c)], expected[static_cast<std::size_t>(a.step())](c, a.id()))
              << name << " agent " << a.id() << " step " << a.step();
        }
        ++*checked;
        inFlight.push_back({a.id(), a.step(), a.position(), a.previousPosition()});
        if (onTurn) onTurn(a);
      }
    }
  }
}

}  // namespace test
}  // namespace vf
