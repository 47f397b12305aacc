#include "variational_formation/ros/pacer.hpp"

namespace vf {

Pacer& Pacer::instance() {
  static Pacer pacer;
  return pacer;
}

void Pacer::at(Clock::time_point due, ros::CallbackQueueInterface* queue, uint64_t owner, std::function<void()> call) {
  std::lock_guard<std::mutex> lock(mutex_);
  const bool earliest = due_.empty() || due < due_.begin()->first;
  due_.emplace(due, Entry{queue, owner, std::move(call)});
  if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
  if (earliest) wake_.notify_all();
}

void Pacer::cancel(uint64_t owner) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto it = due_.begin(); it != due_.end();) it = it->second.owner == owner ? due_.erase(it) : std::next(it);
}

Pacer::~Pacer() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void Pacer::run() {
  const auto grain = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(kGrain));
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    if (due_.empty()) {
      wake_.wait(lock);
      continue;
    }
    const Clock::time_point first = due_.begin()->first;
    if (first - grain > Clock::now()) {
      wake_.wait_until(lock, first - grain);
      continue;  // woken early, or by an earlier call: look again
    }
    // Queued under the lock, so that after cancel() nothing of its owner is queued (the queues
    // never call back into the pacer while holding their own lock).
    const Clock::time_point until = Clock::now() + grain;
    while (!due_.empty() && due_.begin()->first <= until) {
      Entry& e = due_.begin()->second;
      e.queue->addCallback(ros::CallbackInterfacePtr(new QueuedCall(std::move(e.call))), e.owner);
      due_.erase(due_.begin());
    }
  }
}

}  // namespace vf
