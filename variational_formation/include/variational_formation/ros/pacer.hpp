#pragma once

#include <chrono>
#include <cstdint>
#include <condition_variable>
#include <functional>
#include <map>
#include <mutex>
#include <thread>

#include <ros/callback_queue_interface.h>
#include <ros/forwards.h>  // boost::make_shared, without a boost include of the package's own

namespace vf {

/// A function, called once on the callback queue it is added to.
class QueuedCall : public ros::CallbackInterface {
 public:
  explicit QueuedCall(std::function<void()> f) : f_(std::move(f)) {}
  CallResult call() override {
    f_();
    return Success;
  }

 private:
  std::function<void()> f_;
};

/// The same for a callable of type F, in one allocation (no std::function): one per state an
/// agent manager hands from one agent to another.
template <class F>
class CallOnce : public ros::CallbackInterface {
 public:
  explicit CallOnce(F f) : f_(std::move(f)) {}
  CallResult call() override {
    f_();
    return Success;
  }

 private:
  F f_;
};

/// Adds f to `queue` as a CallOnce, under removal id `owner`.
template <class F>
void queueCall(ros::CallbackQueueInterface* queue, F f, uint64_t owner) {
  queue->addCallback(boost::make_shared<CallOnce<F>>(std::move(f)), owner);
}

/**
 * Releases paced steps (an agent at real_time_factor > 0) for every agent of a process from one
 * thread (doc/distributed.md, "Pacing"). A one-shot roscpp timer per agent and step cost a
 * manager of 500 agents a quarter of its steps: roscpp keeps a process's timers in one list,
 * searched linearly whenever one is added or fires. Here one thread sleeps until the earliest due
 * call and then queues, in one wake-up, every call due within kGrain of now, so the agents of a
 * step whose dues differ by less than kGrain go out together. A call therefore runs at most kGrain
 * early; it never runs later for the others' sake.
 */
class Pacer {
 public:
  using Clock = std::chrono::steady_clock;
  /// How early a call may run [s]: the calls due within it of the first go out with it.
  static constexpr double kGrain = 0.001;

  /// The process's pacer (its thread starts with the first call).
  static Pacer& instance();
  /// Queues `call` on `queue`, with owner id `owner`, at `due` (or up to kGrain earlier).
  void at(Clock::time_point due, ros::CallbackQueueInterface* queue, uint64_t owner, std::function<void()> call);
  /// Forgets every call of `owner` not queued yet: none is queued after this returns.
  void cancel(uint64_t owner);
  ~Pacer();

 private:
  struct Entry {
    ros::CallbackQueueInterface* queue;
    uint64_t owner;
    std::function<void()> call;
  };
  Pacer() = default;
  void run();

  std::mutex mutex_;
  std::condition_variable wake_;
  std::multimap<Clock::time_point, Entry> due_;  // guarded by mutex_
  std::thread thread_;
  bool stopping_ = false;  // guarded by mutex_
};

}  // namespace vf
