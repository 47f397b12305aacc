#pragma once

#include <functional>

#include <ros/callback_queue_interface.h>

namespace vf {

/**
 * A call every `period` seconds on a callback queue, as a roscpp WallTimer makes it, but driven by
 * one thread per process for every PeriodicCall in it (doc/distributed.md, "Threads"). roscpp
 * keeps a process's timers in one list that it sorts whenever one fires, comparing entries by a
 * linear search: with a timer per agent, a manager of 1000 agents spent 90% of its time in
 * TimerManager::findTimer and stalled. The call runs on the queue, one at a time with the owner's
 * other callbacks; a call still waiting there is not queued twice.
 */
class PeriodicCall {
 public:
  PeriodicCall() = default;
  /// Starts calling `call` on `queue` every `period` (> 0) seconds, the first one period from now.
  PeriodicCall(ros::CallbackQueueInterface* queue, double period, std::function<void()> call);
  /// Stops: no call starts afterwards, and one in progress on another thread has ended.
  ~PeriodicCall();
  PeriodicCall(const PeriodicCall&) = delete;
  PeriodicCall& operator=(const PeriodicCall&) = delete;
  /// Stops this one's calls, then takes over `other`'s.
  PeriodicCall& operator=(PeriodicCall&& other) noexcept;

  struct Entry;

 private:
  void stop();
  Entry* entry_ = nullptr;
};

}  // namespace vf
