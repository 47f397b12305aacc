#pragma once

#include <cstddef>
#include <deque>

#include <ros/ros.h>  // boost::shared_ptr and boost::make_shared, as roscpp's messages use them

namespace vf {

/**
 * Messages of one publisher reused once nothing else holds them (AgentNode's own states, and the
 * benchmarks that stand for an agent_manager's agents): a message published as a pointer to const
 * goes to subscribers in the same process as that very object, so it cannot be refilled while any
 * of them, a queue, a latch or a history, still holds it. next() takes the oldest message handed
 * out if its use count is 1 (only this pool holds it, and nothing can take it again), else makes
 * a new one; its vectors and strings keep their memory. At most `kept` are held: past that, the
 * oldest is left to its holders.
 */
template <class Message>
class ReusedMessages {
 public:
  explicit ReusedMessages(std::size_t kept) : kept_(kept) {}

  /// A message to fill and publish (its old contents, if reused, are still in it).
  boost::shared_ptr<Message> next() {
    boost::shared_ptr<Message> m;
    if (!held_.empty() && held_.front().use_count() == 1) {
      m = std::move(held_.front());
      held_.pop_front();
    } else {
      m = boost::make_shared<Message>();
    }
    held_.push_back(m);
    if (held_.size() > kept_) held_.pop_front();
    return m;
  }

 private:
  std::size_t kept_;
  std::deque<boost::shared_ptr<Message>> held_;  // handed out, oldest first
};

}  // namespace vf
