// CallPool (include/variational_formation/ros/service_call.hpp): the bounded set of threads the
// monitor, recorder and agents make their recall and history calls on. No master needed: the
// jobs here are plain functions that stand for calls, some of which never answer in time.
#include <atomic>
#include <chrono>
#include <future>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "variational_formation/ros/service_call.hpp"

namespace {
using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

TEST(CallPool, ManyCallsShareAFixedNumberOfThreads) {
  vf::CallPool pool(8);
  std::atomic<int> done{0}, concurrent{0}, most{0};
  std::vector<std::future<void>> finished;
  for (int k = 0; k < 200; ++k) {  // a monitor restart at 200 agents
    auto p = std::make_shared<std::promise<void>>();
    finished.push_back(p->get_future());
    pool.submit([&, p](bool run) {
      if (run) {
        const int now = ++concurrent;
        int seen = most.load();
        while (now > seen && !most.compare_exchange_weak(seen, now)) {
        }
        std::this_thread::sleep_for(milliseconds(2));
        --concurrent;
        ++done;
      }
      p->set_value();
    });
  }
  for (auto& f : finished) f.wait();
  EXPECT_EQ(done.load(), 200);
  EXPECT_LE(pool.threads(), 8u);
  EXPECT_LE(most.load(), 8);
  EXPECT_GE(most.load(), 2) << "the calls did not overlap at all";
}

TEST(CallPool, ACallThatNeverAnswersHoldsOneThreadOnly) {
  vf::CallPool pool(2);
  std::promise<void> release;
  std::shared_future<void> gate = release.get_future().share();
  pool.submit([gate](bool run) {
    if (run) gate.wait();  // a server stopped with SIGSTOP
  });
  std::promise<bool> other;
  pool.submit([&other](bool run) { other.set_value(run); });
  auto answer = other.get_future();
  ASSERT_EQ(answer.wait_for(std::chrono::seconds(5)), std::future_status::ready);
  EXPECT_TRUE(answer.get());
  release.set_value();
}

TEST(CallPool, ClosingGivesUpQueuedCallsAndWaitsForTheRunningOnesBriefly) {
  std::promise<void> release;
  std::shared_future<void> gate = release.get_future().share();
  std::atomic<int> ran{0}, givenUp{0};
  const auto start = Clock::now();
  {
    vf::CallPool pool(1);
    pool.submit([gate, &ran](bool run) {
      if (run) {
        ++ran;
        gate.wait_for(std::chrono::seconds(10));  // blocked past the 2 s the pool waits
      }
    });
    std::this_thread::sleep_for(milliseconds(50));
    for (int k = 0; k < 5; ++k) {
      pool.submit([&ran, &givenUp](bool run) { run ? ++ran : ++givenUp; });
    }
  }  // the destructor: the five queued calls are given up, the blocked one is left behind
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  EXPECT_EQ(ran.load(), 1);
  EXPECT_EQ(givenUp.load(), 5);
  EXPECT_GE(seconds, 1.9);
  EXPECT_LT(seconds, 5.0) << "closing waited for a call that never answers";
  release.set_value();
  std::this_thread::sleep_for(milliseconds(50));  // let the detached thread leave before the test ends
}

TEST(CallPool, ClosingJoinsThreadsWhoseCallsEnded) {
  const auto start = Clock::now();
  std::atomic<int> ran{0};
  {
    vf::CallPool pool(4);
    for (int k = 0; k < 4; ++k) pool.submit([&ran](bool run) { ran += run ? 1 : 0; });
    std::this_thread::sleep_for(milliseconds(100));
  }
  EXPECT_EQ(ran.load(), 4);
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - start).count(), 1.5);
}
}  // namespace
