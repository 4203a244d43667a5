// A minimal deterministic parallel-for: tasks 0..n-1 are handed to `threads`
// workers in order of an atomic counter; results must be stored per task by
// the caller, so the outcome does not depend on the number of threads.
#pragma once
#include <atomic>
#include <functional>
#include <thread>
#include <vector>

namespace skyfarm {

// threads <= 0: all hardware threads.
inline int resolve_thread_count(int threads) {
  if (threads > 0) return threads;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : static_cast<int>(hw);
}

inline void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t task, int worker)>& body) {
  const int T = std::max(1, std::min<int>(resolve_thread_count(threads), static_cast<int>(std::max<std::size_t>(n, 1))));
  std::atomic<std::size_t> next{0};
  auto run = [&](int worker) {
    for (std::size_t i = next++; i < n; i = next++) body(i, worker);
  };
  if (T == 1) {
    run(0);
    return;
  }
  std::vector<std::thread> pool;
  for (int w = 1; w < T; ++w) pool.emplace_back(run, w);
  run(0);
  for (auto& t : pool) t.join();
}

}  // namespace skyfarm
