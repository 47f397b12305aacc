// TopicAudience (doc/distributed.md, "Local delivery"): an agent's topic is published only while
// a subscriber outside its process is connected, and each one that connects gets the newest state.
#include <gtest/gtest.h>

#include <memory>

#include "variational_formation_core/protocol/topic_audience.hpp"

namespace vf {
namespace {

using State = std::shared_ptr<const long>;  // a state is its step here

State at(long step) { return std::make_shared<const long>(step); }

TEST(TopicAudience, PublishesOnlyWhileSomeoneOutsideListens) {
  TopicAudience<State> a("/formation/manager");
  EXPECT_FALSE(a.published(at(0)));  // nobody connected
  // The manager's own agents (its process's subscription) do not count: they use the exchange.
  EXPECT_EQ(a.connected("/formation/manager"), nullptr);
  EXPECT_FALSE(a.published(at(1)));
  EXPECT_EQ(a.outside(), 0);
  // A subscriber outside (another manager, the monitor, rostopic) gets the newest at once...
  const State first = a.connected("/formation/manager_b");
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(*first, 1);
  // ... and every later state on the topic.
  EXPECT_TRUE(a.published(at(2)));
  EXPECT_EQ(*a.connected("/rostopic_123"), 2);
  EXPECT_EQ(a.outside(), 2);
  a.disconnected("/formation/manager");  // its own process leaving changes nothing
  a.disconnected("/formation/manager_b");
  EXPECT_TRUE(a.published(at(3)));
  a.disconnected("/rostopic_123");
  EXPECT_FALSE(a.published(at(4)));
  a.disconnected("/rostopic_123");  // one disconnection too many does not go below zero
  EXPECT_EQ(a.outside(), 0);
  EXPECT_EQ(*a.connected("/late"), 4);
}

TEST(TopicAudience, NothingToSendBeforeTheFirstState) {
  TopicAudience<State> a("/m");
  EXPECT_EQ(a.connected("/early"), nullptr);
  EXPECT_EQ(a.outside(), 1);
  EXPECT_TRUE(a.published(at(0)));
}

}  // namespace
}  // namespace vf
