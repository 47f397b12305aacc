#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <ros/ros.h>

namespace vf {

/**
 * A fixed number of threads for service calls that may never answer: roscpp's own call has no
 * timeout, and a stopped (SIGSTOP) server blocks its caller for as long as it is stopped. Calls
 * queue when every thread is busy; a call still queued at its deadline is given up without being
 * made. The threads start on first use. Destroying the pool gives up the queued calls and waits
 * up to 2 s for those under way (ros::shutdown ends them by closing their connections); any still
 * blocked after that are left to end with the process, and it says how many.
 */
class CallPool {
 public:
  explicit CallPool(std::size_t threads) : size_(threads < 1 ? 1 : threads), shared_(std::make_shared<Shared>()) {}
  ~CallPool();
  CallPool(const CallPool&) = delete;
  CallPool& operator=(const CallPool&) = delete;

  /**
   * Calls every service `names[k]` with `services[k]`, each only if it exists, and gives up on
   * those that have not answered within `timeout` seconds. @return per service, whether its call
   * succeeded (then `services[k]` holds the response).
   */
  template <class Service>
  std::vector<bool> callAll(const std::vector<std::string>& names, std::vector<Service>& services, double timeout) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
    std::vector<std::shared_ptr<Service>> shared;
    std::vector<std::future<bool>> results;
    for (std::size_t k = 0; k < names.size(); ++k) {
      auto call = std::make_shared<Service>(services[k]);
      auto done = std::make_shared<std::promise<bool>>();
      results.push_back(done->get_future());
      shared.push_back(call);
      submit([name = names[k], call, done, deadline](bool run) {
        run = run && std::chrono::steady_clock::now() < deadline;
        done->set_value(run && ros::service::exists(name, false) && ros::service::call(name, *call));
      });
    }
    std::vector<bool> ok(names.size(), false);
    for (std::size_t k = 0; k < names.size(); ++k) {
      ok[k] = results[k].wait_until(deadline) == std::future_status::ready && results[k].get();
      if (ok[k]) services[k] = *shared[k];
    }
    return ok;
  }

  /// Runs `job` on a pool thread, once: with true to do its work, or with false when the pool is
  /// closing. A thread is started only when every one started so far is busy.
  void submit(std::function<void(bool)> job);
  /// Threads started so far (at most the pool's size).
  std::size_t threads() const;

 private:
  /// What the threads share with the pool; a thread left blocked at closing keeps it alive.
  struct Shared {
    std::mutex mutex;
    std::condition_variable wake, exited;
    std::deque<std::function<void(bool)>> jobs;
    std::size_t busy = 0;     // threads inside a job
    std::size_t running = 0;  // threads not yet exited
    bool stop = false;
  };
  static void work(std::shared_ptr<Shared> shared);

  const std::size_t size_;
  std::shared_ptr<Shared> shared_;
  std::vector<std::thread> threads_;  // guarded by shared_->mutex
};

/// The process's pool for recall, history and catch-up calls: 8 threads at most, whatever the
/// number of agents (a monitor restart at 200 agents makes 200 calls).
CallPool& recallPool();

/// recallPool().callAll(names, services, timeout).
template <class Service>
std::vector<bool> callAllWithTimeout(const std::vector<std::string>& names, std::vector<Service>& services,
                                     double timeout) {
  return recallPool().callAll(names, services, timeout);
}

}  // namespace vf
