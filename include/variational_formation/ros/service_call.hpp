#pragma once

#include <chrono>
#include <future>
#include <memory>
#include <string>
#include <thread>

#include <ros/ros.h>

namespace vf {

/**
 * Calls a service if it exists, giving up after `timeout` seconds: roscpp's own call has no
 * timeout, and a stopped (SIGSTOP) server would block the caller for as long as it is stopped.
 * A call that times out finishes in a detached thread. @return true if the call succeeded.
 */
template <class Service>
bool callWithTimeout(const std::string& name, Service& service, double timeout) {
  if (!ros::service::exists(name, false)) return false;
  auto shared = std::make_shared<Service>(service);
  auto done = std::make_shared<std::promise<bool>>();
  std::future<bool> result = done->get_future();
  std::thread([name, shared, done] { done->set_value(ros::service::call(name, *shared)); }).detach();
  if (result.wait_for(std::chrono::duration<double>(timeout)) != std::future_status::ready || !result.get()) {
    return false;
  }
  service = *shared;
  return true;
}

}  // namespace vf
