#include "variational_formation_core/common/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

namespace vf {

void parallelFor(int tasks, int threads, const std::function<void(int)>& task,
                 const std::function<long(int)>& weight,
                 const std::function<void(long)>& progress) {
  long total = 0;
  for (int t = 0; t < tasks; ++t) total += weight ? weight(t) : 1;
  std::atomic<int> next{0};
  std::atomic<long> done{0};
  const auto worker = [&] {
    for (int t = next++; t < tasks; t = next++) {
      task(t);
      done += weight ? weight(t) : 1;
    }
  };
  const int extra = std::max(1, threads) - 1;
  std::vector<std::thread> pool;
  for (int t = 0; t < extra; ++t) pool.emplace_back(worker);
  if (progress) {
    // The calling thread reports progress while the pool works, then joins in.
    std::thread last(worker);
    while (done.load() < total) {
      progress(done.load());
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    last.join();
    progress(done.load());
  } else {
    worker();
  }
  for (auto& t : pool) t.join();
}

}  // namespace vf
