#include "variational_formation/ros/service_call.hpp"

#include <cstdio>

namespace vf {

CallPool::~CallPool() {
  std::unique_lock<std::mutex> lock(shared_->mutex);
  shared_->stop = true;
  std::deque<std::function<void(bool)>> queued;
  queued.swap(shared_->jobs);
  shared_->wake.notify_all();
  lock.unlock();
  for (auto& job : queued) job(false);  // given up, here and now
  lock.lock();
  shared_->exited.wait_for(lock, std::chrono::seconds(2), [this] { return shared_->running == 0; });
  const std::size_t blocked = shared_->running;
  lock.unlock();
  for (std::thread& t : threads_) {
    if (blocked == 0) {
      t.join();
    } else {
      t.detach();  // a call blocked on a stopped server: the process ends it
    }
  }
  if (blocked > 0) {
    std::fprintf(stderr, "service calls: %zu call(s) still blocked at shutdown (a stopped server?); left to end "
                 "with the process\n", blocked);
  }
}

std::size_t CallPool::threads() const {
  std::lock_guard<std::mutex> lock(shared_->mutex);
  return threads_.size();
}

void CallPool::submit(std::function<void(bool)> job) {
  std::unique_lock<std::mutex> lock(shared_->mutex);
  if (shared_->stop) {
    lock.unlock();
    job(false);
    return;
  }
  shared_->jobs.push_back(std::move(job));
  if (threads_.size() < size_ && shared_->busy + shared_->jobs.size() > threads_.size()) {
    ++shared_->running;
    threads_.emplace_back(&CallPool::work, shared_);
  }
  shared_->wake.notify_one();
}

void CallPool::work(std::shared_ptr<Shared> shared) {
  std::unique_lock<std::mutex> lock(shared->mutex);
  for (;;) {
    shared->wake.wait(lock, [&] { return shared->stop || !shared->jobs.empty(); });
    if (shared->jobs.empty()) break;  // closing, nothing left
    std::function<void(bool)> job = std::move(shared->jobs.front());
    shared->jobs.pop_front();
    const bool run = !shared->stop;
    ++shared->busy;
    lock.unlock();
    job(run);
    lock.lock();
    --shared->busy;
  }
  --shared->running;
  shared->exited.notify_all();
}

CallPool& recallPool() {
  static CallPool pool(8);
  return pool;
}

}  // namespace vf
