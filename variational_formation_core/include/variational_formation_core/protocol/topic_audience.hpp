#pragma once

#include <string>
#include <utility>

namespace vf {

/**
 * Who else needs an agent's state on its middleware topic, when its own process gets it from a
 * LocalExchange: the rule of doc/distributed.md, "Local delivery". The agent publishes on the topic
 * only while a subscriber outside its process is connected; a connection from its own process is
 * the other agents' (they listen to the exchange) and does not count. A subscriber that connects
 * gets the newest state at once, as the latched topic gave it before. Not thread-safe: the
 * publisher's connection callbacks and its publishing run on one thread (the agent's queue).
 */
template <class State>
class TopicAudience {
 public:
  /// @param self the node name of this process (the caller id its own subscriptions carry).
  explicit TopicAudience(std::string self) : self_(std::move(self)) {}

  /// The agent published `state`. @return whether it must also go out on the topic.
  bool published(const State& state) {
    newest_ = state;
    return outside_ > 0;
  }
  /// Subscriber `name` connected. @return the state to send it now: the newest, or empty (none
  /// yet, or `name` is this process).
  State connected(const std::string& name) {
    if (name == self_) return State();
    ++outside_;
    return newest_;
  }
  /// Subscriber `name` disconnected.
  void disconnected(const std::string& name) {
    if (name != self_ && outside_ > 0) --outside_;
  }
  /// How many subscribers outside this process are connected.
  int outside() const { return outside_; }

 private:
  std::string self_;
  State newest_;
  int outside_ = 0;
};

}  // namespace vf
