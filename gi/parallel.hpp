// Work items 0 .. count-1 handed to threads one at a time (whichever thread
// is free takes the next), for the CPU renderers and tracers: the result of
// an item must not depend on which thread runs it, so outputs are the same
// for any thread count.
//
// The caller's cancel token (protocol/cancel.hpp) is installed on every
// worker and checked before each item; the first exception an item throws
// (Cancelled, a failed check) stops the other workers at their next item and
// is rethrown on the caller's thread once all have joined, so no exception
// ever leaves a std::thread (which would end the process).
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "protocol/cancel.hpp"
#include "protocol/turns.hpp"

namespace beamcast {

// threads <= 0: std::thread::hardware_concurrency(); never more threads than items.
template <class Body>
void parallel_items(int count, int threads, Body&& body) {
  const int hw = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int n = std::min(count, threads > 0 ? threads : hw);
  const CancelToken* token = current_cancel_token();
  std::atomic<int> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr first_error;
  std::mutex error_mu;
  auto worker = [&] {
    const CancelScope scope(token);
    try {
      for (int i = next.fetch_add(1); i < count && !failed.load(std::memory_order_relaxed);
           i = next.fetch_add(1)) {
        check_cancel();
        body(i);
      }
    } catch (...) {
      std::lock_guard lock(error_mu);
      if (!first_error) first_error = std::current_exception();
      failed.store(true);
    }
  };
  if (n <= 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    pool.reserve(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) pool.emplace_back(worker);
    for (auto& t : pool) t.join();
  }
  if (first_error) std::rethrow_exception(first_error);
}

// parallel_items for a render that may give turns (protocol/turns.hpp): the
// items run on `threads` workers while the caller's thread watches, and
// every `every` it offers a turn (turn_point). When one is due the workers
// stop taking items, those in progress finish, `before` runs and then the
// turn, both on the caller's thread, and the items go on. Results, errors
// and cancellation as parallel_items; no hook installed: parallel_items.
template <class Body, class Before>
void parallel_items_with_turns(int count, int threads, Body&& body, Before&& before,
                               std::chrono::milliseconds every) {
  if (!turn_hook_installed() || count <= 0) {
    parallel_items(count, threads, body);
    return;
  }
  const int hw = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int n = std::min(count, threads > 0 ? threads : hw);
  const CancelToken* token = current_cancel_token();
  std::mutex mu;
  std::condition_variable cv;
  int next = 0;      // the next item to take
  int running = 0;   // items in progress
  int finished = 0;  // workers that have stopped
  bool paused = false;
  bool failed = false;
  std::exception_ptr first_error;
  auto worker = [&] {
    const CancelScope scope(token);
    for (;;) {
      int i = 0;
      {
        std::unique_lock lock(mu);
        cv.wait(lock, [&] { return !paused || failed; });
        if (failed || next >= count) break;
        i = next++;
        ++running;
      }
      try {
        check_cancel();
        body(i);
      } catch (...) {
        std::lock_guard lock(mu);
        if (!first_error) first_error = std::current_exception();
        failed = true;
      }
      {
        std::lock_guard lock(mu);
        --running;
      }
      cv.notify_all();
    }
    {
      std::lock_guard lock(mu);
      ++finished;
    }
    cv.notify_all();
  };
  std::vector<std::thread> pool;
  pool.reserve(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) pool.emplace_back(worker);
  for (;;) {
    {
      std::unique_lock lock(mu);
      if (cv.wait_for(lock, every, [&] { return finished == n; })) break;
    }
    try {
      turn_point([&] {
        {
          std::unique_lock lock(mu);
          paused = true;
          cv.wait(lock, [&] { return running == 0; });
        }
        before();
      });
    } catch (...) {
      std::lock_guard lock(mu);
      if (!first_error) first_error = std::current_exception();
      failed = true;
    }
    {
      std::lock_guard lock(mu);
      paused = false;
    }
    cv.notify_all();
  }
  for (auto& t : pool) t.join();
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace beamcast
