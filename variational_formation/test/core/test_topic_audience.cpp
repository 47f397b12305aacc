// TopicAudience (doc/distributed.md, "Local delivery"): an agent's topic stays silent until a
// subscriber outside its process connects, then carries every state for good; a subscriber is
// sent the newest state from the connect callback exactly when neither the topic's latch nor its
// broadcast gives it one.
#include <gtest/gtest.h>

#include <memory>

#include "variational_formation_core/protocol/topic_audience.hpp"

namespace vf {
namespace {

using State = std::shared_ptr<const long>;  // a state is its step here

State at(long step) { return std::make_shared<const long>(step); }

TEST(TopicAudience, SilentUntilSomeoneOutsideListensThenLiveForGood) {
  TopicAudience<State> a("/formation/manager");
  EXPECT_FALSE(a.published(at(0)));  // nobody connected
  // The manager's own agents (its process's subscription) do not count: they use the exchange.
  EXPECT_EQ(a.connected("/formation/manager"), nullptr);
  EXPECT_FALSE(a.published(at(1)));
  EXPECT_FALSE(a.live());
  // A subscriber outside (another manager, the monitor, rostopic) gets the newest at once...
  const State first = a.connected("/formation/manager_b");
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(*first, 1);
  EXPECT_TRUE(a.live());
  // ... and every later state on the topic, which latches it.
  EXPECT_TRUE(a.published(at(2)));
  // A later subscriber gets step 2 from the latch (or the broadcast): nothing more from here,
  // which would reach it twice.
  EXPECT_EQ(a.connected("/rostopic_123"), nullptr);
  EXPECT_TRUE(a.published(at(3)));
  EXPECT_TRUE(a.published(at(4)));  // live for good: the latch must never hold a stale state
}

TEST(TopicAudience, SubscribersBeforeTheFirstLiveStateAreEachSentTheNewest) {
  TopicAudience<State> a("/m");
  EXPECT_EQ(a.connected("/early"), nullptr);  // nothing to send before the first state
  EXPECT_TRUE(a.live());
  EXPECT_TRUE(a.published(at(0)));
  EXPECT_EQ(a.connected("/later"), nullptr);  // step 0 went out live, latched

  TopicAudience<State> b("/m");
  EXPECT_FALSE(b.published(at(7)));
  // Two connect callbacks before the next state: neither connection got step 7 from the topic.
  EXPECT_EQ(*b.connected("/one"), 7);
  EXPECT_EQ(*b.connected("/two"), 7);
  EXPECT_TRUE(b.published(at(8)));
  EXPECT_EQ(b.connected("/three"), nullptr);
}

}  // namespace
}  // namespace vf
