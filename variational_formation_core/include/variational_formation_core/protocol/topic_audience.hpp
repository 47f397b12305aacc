#pragma once

#include <string>
#include <utility>

namespace vf {

/**
 * Whether an agent's state must go out on its middleware topic, when its own process gets it from
 * a LocalExchange: the rule of doc/distributed.md, "Local delivery". The topic stays silent until
 * the first subscriber from outside the process connects (a connection from its own process is
 * the other agents', which listen to the exchange, and does not count); from then on every state
 * goes out on it, latched, for good. The connecting subscriber that makes it live is sent the
 * newest state, and so is any other that connects before the first state goes out live; a later
 * one gets it from the latch, which holds the newest then. Why for good: the middleware's latch
 * and its broadcast hand a new subscriber the newest state exactly once, whenever its connection
 * is made; a topic that went silent again would latch a stale state, and a state sent from the
 * connect callback of a live topic may reach the subscriber twice (once broadcast, once sent).
 * Not thread-safe: the publisher's connect callbacks and its publishing run on one thread (the
 * agent's queue).
 */
template <class State>
class TopicAudience {
 public:
  /// @param self the node name of this process (the caller id its own subscriptions carry).
  explicit TopicAudience(std::string self) : self_(std::move(self)) {}

  /// The agent published `state`. @return whether it must also go out on the topic.
  bool published(const State& state) {
    newest_ = state;
    sentLive_ = sentLive_ || live_;
    return live_;
  }
  /// Subscriber `name` connected. @return the state to send it now: the newest, or empty (none
  /// yet, `name` is this process, or the topic's latch and broadcast already give it).
  State connected(const std::string& name) {
    if (name == self_) return State();
    live_ = true;
    return sentLive_ ? State() : newest_;
  }
  /// Whether the topic is live (a subscriber from outside has connected).
  bool live() const { return live_; }

 private:
  std::string self_;
  State newest_;
  bool live_ = false;      // an outside subscriber connected: every state goes out on the topic
  bool sentLive_ = false;  // a state went out on the live topic: its latch holds the newest
};

}  // namespace vf
