// Threads with a stack size the server chooses rather than inherits
// (std::thread takes RLIMIT_STACK's, which a user's ulimit can shrink). The
// network threads run the recursive walks over client JSON (copy, merge patch,
// validation, echo); their depth is bounded by max_json_depth (PROTOCOL.md,
// "Limits"), and kServerThreadStackBytes leaves a wide margin above what that
// depth needs (tests/server/test_hostile.cpp renders, echoes and merges at the
// limit).
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include <pthread.h>

namespace beamcast {

inline constexpr std::size_t kServerThreadStackBytes = 8u << 20;

// Cores this process may run on (its affinity mask; hardware_concurrency if
// that cannot be read).
int usable_cores();
// The encode pool's default size (--encode-threads 0): the cores less one per
// render worker and per network thread, at least 2 (one frame encodes while
// the next one's slice is handed over; 2 was the default before issue 39).
int default_encode_threads(int cores, int render_workers, int network_threads);

class SizedThread {
 public:
  // Starts `fn` on a new thread with a stack of `stack_bytes`; throws
  // std::system_error if the thread cannot be created.
  explicit SizedThread(std::function<void()> fn, std::size_t stack_bytes = kServerThreadStackBytes);
  SizedThread(SizedThread&& other) noexcept;
  SizedThread& operator=(SizedThread&&) = delete;
  SizedThread(const SizedThread&) = delete;
  ~SizedThread();  // joins if still joinable

  bool joinable() const { return joinable_; }
  void join();

 private:
  pthread_t thread_{};
  bool joinable_ = false;
};

// A few SizedThreads that run posted work, first posted first started.
class WorkPool {
 public:
  explicit WorkPool(int threads);
  WorkPool(const WorkPool&) = delete;
  WorkPool& operator=(const WorkPool&) = delete;
  ~WorkPool() { stop(); }
  void post(std::function<void()> fn);
  // Lets the work already started finish, drops the rest (destroyed
  // unrun), joins the threads. Work posted afterwards is dropped too.
  void stop();

 private:
  void run();
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> queue_;
  bool stopping_ = false;
  std::vector<SizedThread> threads_;
};

}  // namespace beamcast
