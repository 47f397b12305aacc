#pragma once

#include <chrono>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <ros/ros.h>

namespace vf {

/**
 * Calls several services at once, each only if it exists, and gives up on those that have not
 * answered within `timeout` seconds: roscpp's own call has no timeout, and a stopped (SIGSTOP)
 * server would block the caller for as long as it is stopped. A call that times out finishes in a
 * detached thread. @return per service, whether its call succeeded (then `services[k]` holds the
 * response).
 */
template <class Service>
std::vector<bool> callAllWithTimeout(const std::vector<std::string>& names, std::vector<Service>& services,
                                     double timeout) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
  std::vector<std::shared_ptr<Service>> shared;
  std::vector<std::future<bool>> results;
  for (std::size_t k = 0; k < names.size(); ++k) {
    auto call = std::make_shared<Service>(services[k]);
    auto done = std::make_shared<std::promise<bool>>();
    results.push_back(done->get_future());
    shared.push_back(call);
    std::thread([name = names[k], call, done] {
      done->set_value(ros::service::exists(name, false) && ros::service::call(name, *call));
    }).detach();
  }
  std::vector<bool> ok(names.size(), false);
  for (std::size_t k = 0; k < names.size(); ++k) {
    ok[k] = results[k].wait_until(deadline) == std::future_status::ready && results[k].get();
    if (ok[k]) services[k] = *shared[k];
  }
  return ok;
}

}  // namespace vf
