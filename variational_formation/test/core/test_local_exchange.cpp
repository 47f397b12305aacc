// LocalExchange (doc/distributed.md, "Local delivery"): every listener gets every state of its
// source once, in order, a late one the newest first, also while states are delivered from
// another thread.
#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/protocol/local_exchange.hpp"

namespace vf {
namespace {

using State = std::shared_ptr<const long>;  // a state is its step here
using Exchange = LocalExchange<State>;

State at(long step) { return std::make_shared<const long>(step); }

/// The steps a listener got, with their source.
struct Got {
  std::mutex mutex;
  std::vector<std::pair<int, long>> states;
  Exchange::Handler handler() {
    return [this](int source, const State& s) {
      std::lock_guard<std::mutex> lock(mutex);
      states.emplace_back(source, *s);
    };
  }
};

TEST(LocalExchange, HostsOnlyItsAgents) {
  Exchange e({0, 2, 5});
  EXPECT_TRUE(e.hosts(0));
  EXPECT_TRUE(e.hosts(5));
  EXPECT_FALSE(e.hosts(1));
  EXPECT_FALSE(e.hosts(6));
  EXPECT_FALSE(e.hosts(-1));
  EXPECT_EQ(e.newest(1), nullptr);
  try {
    e.deliver(1, at(0));
    FAIL() << "delivered for an agent that is not hosted";
  } catch (const InvalidInput& error) {
    EXPECT_EQ(std::string(error.what()), "local exchange: agent 1 is not in this process");
  }
  Got got;
  EXPECT_THROW(e.listen(3, 1, got.handler()), InvalidInput);
  EXPECT_THROW(Exchange({0, -2}), InvalidInput);
}

TEST(LocalExchange, ListenersGetEveryStateInOrderAndALateOneTheNewestFirst) {
  Exchange e({0, 1});
  Got early, late, other;
  e.listen(0, 1, early.handler());  // before anything: nothing held, nothing handed
  EXPECT_TRUE(early.states.empty());
  e.listen(1, 1, other.handler());
  for (long k = 0; k <= 3; ++k) e.deliver(0, at(k));
  e.listen(0, 2, late.handler());
  EXPECT_EQ(*e.newest(0), 3);
  for (long k = 4; k <= 5; ++k) e.deliver(0, at(k));
  e.deliver(1, at(0));
  EXPECT_EQ(early.states, (std::vector<std::pair<int, long>>{{0, 0}, {0, 1}, {0, 2}, {0, 3}, {0, 4}, {0, 5}}));
  EXPECT_EQ(late.states, (std::vector<std::pair<int, long>>{{0, 3}, {0, 4}, {0, 5}}));
  EXPECT_EQ(other.states, (std::vector<std::pair<int, long>>{{1, 0}}));
}

TEST(LocalExchange, NothingReachesAListenerThatStopped) {
  Exchange e({0, 1});
  Got stays, stops;
  e.listen(0, 1, stays.handler());
  e.listen(0, 2, stops.handler());
  e.listen(1, 2, stops.handler());
  e.deliver(0, at(0));
  e.stopListening(2);
  e.deliver(0, at(1));
  e.deliver(1, at(0));
  EXPECT_EQ(stays.states.size(), 2u);
  EXPECT_EQ(stops.states, (std::vector<std::pair<int, long>>{{0, 0}}));
}

// Listeners that begin while another thread delivers: each gets a run of consecutive steps that
// ends at the last one, whenever it began (nothing lost or repeated between newest and next).
TEST(LocalExchange, ListenersThatBeginDuringDeliveryMissNothing) {
  Exchange e({0});
  constexpr long kSteps = 20000;
  constexpr int kListeners = 40;
  std::vector<Got> got(kListeners);
  std::atomic<bool> go{false};
  std::thread deliverer([&] {
    while (!go) std::this_thread::yield();
    for (long k = 0; k <= kSteps; ++k) e.deliver(0, at(k));
  });
  go = true;
  for (int l = 0; l < kListeners; ++l) {
    e.listen(0, static_cast<std::uintptr_t>(l), got[static_cast<std::size_t>(l)].handler());
    std::this_thread::yield();
  }
  deliverer.join();
  for (int l = 0; l < kListeners; ++l) {
    const auto& s = got[static_cast<std::size_t>(l)].states;
    ASSERT_FALSE(s.empty()) << "listener " << l;
    for (std::size_t k = 1; k < s.size(); ++k) ASSERT_EQ(s[k].second, s[k - 1].second + 1) << "listener " << l;
    EXPECT_EQ(s.back().second, kSteps) << "listener " << l;
  }
}

}  // namespace
}  // namespace vf
