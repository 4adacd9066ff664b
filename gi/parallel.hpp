// Work items 0 .. count-1 handed to threads one at a time (whichever thread
// is free takes the next), for the CPU renderers and tracers: the result of
// an item must not depend on which thread runs it, so outputs are the same
// for any thread count.
#pragma once

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace beamcast {

// threads <= 0: std::thread::hardware_concurrency(); never more threads than items.
template <class Body>
void parallel_items(int count, int threads, Body&& body) {
  const int hw = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int n = std::min(count, threads > 0 ? threads : hw);
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int i = next.fetch_add(1); i < count; i = next.fetch_add(1)) body(i);
  };
  if (n <= 1) {
    worker();
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
}

}  // namespace beamcast
