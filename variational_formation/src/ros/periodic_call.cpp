#include "variational_formation/ros/periodic_call.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <set>
#include <thread>

namespace vf {

using Clock = std::chrono::steady_clock;

struct PeriodicCall::Entry {
  ros::CallbackQueueInterface* queue;
  Clock::duration period;
  std::function<void()> call;
  Clock::time_point due;
  bool queued = false;  // a call waits on the queue (guarded by the ticker's mutex)
};

namespace {

/// The process's one thread that queues every PeriodicCall when it is due.
class Ticker {
 public:
  static Ticker& instance() {
    static Ticker ticker;
    return ticker;
  }
  void add(PeriodicCall::Entry* e) {
    std::lock_guard<std::mutex> lock(mutex_);
    entries_.insert(e);
    if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
    wake_.notify_all();
  }
  /// After this, the ticker never queues `e` again.
  void remove(PeriodicCall::Entry* e) {
    std::lock_guard<std::mutex> lock(mutex_);
    entries_.erase(e);
  }
  /// A queued call of `e` starts (on its queue's thread): it may be queued again.
  void started(PeriodicCall::Entry* e) {
    std::lock_guard<std::mutex> lock(mutex_);
    e->queued = false;
  }
  ~Ticker() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

 private:
  class Call : public ros::CallbackInterface {
   public:
    explicit Call(PeriodicCall::Entry* e) : entry_(e) {}
    // Runs under the queue's lock for this entry's id: PeriodicCall's stop() waits for it.
    CallResult call() override {
      Ticker::instance().started(entry_);
      entry_->call();
      return Success;
    }

   private:
    PeriodicCall::Entry* entry_;
  };

  void run() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stopping_) {
      const Clock::time_point now = Clock::now();
      Clock::time_point next = now + std::chrono::seconds(1);
      for (PeriodicCall::Entry* e : entries_) {
        if (e->due <= now) {
          if (!e->queued) {
            e->queued = true;
            e->queue->addCallback(ros::CallbackInterfacePtr(new Call(e)), reinterpret_cast<uint64_t>(e));
          }
          while (e->due <= now) e->due += e->period;
        }
        next = std::min(next, e->due);
      }
      // At most 20 wake-ups a second, however many calls there are (a call may be 50 ms late).
      wake_.wait_until(lock, std::max(next, now + std::chrono::milliseconds(50)));
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  std::set<PeriodicCall::Entry*> entries_;
  std::thread thread_;
  bool stopping_ = false;
};

}  // namespace

PeriodicCall::PeriodicCall(ros::CallbackQueueInterface* queue, double period, std::function<void()> call)
    : entry_(new Entry{queue, std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period)),
                       std::move(call), Clock::now(), false}) {
  entry_->due += entry_->period;
  Ticker::instance().add(entry_);
}

PeriodicCall::~PeriodicCall() { stop(); }

PeriodicCall& PeriodicCall::operator=(PeriodicCall&& other) noexcept {
  if (this != &other) {
    stop();
    entry_ = other.entry_;
    other.entry_ = nullptr;
  }
  return *this;
}

void PeriodicCall::stop() {
  if (!entry_) return;
  Ticker::instance().remove(entry_);
  // Drops a queued call and waits for one in progress (the queue's removal lock).
  entry_->queue->removeByID(reinterpret_cast<uint64_t>(entry_));
  delete entry_;
  entry_ = nullptr;
}

}  // namespace vf
