// Cancelling long CPU work from outside it (issue 43): a request's wall-clock
// deadline (the server's max_render_ms), its client going away, and the
// server's shutdown.
//
// The thread that starts a piece of work installs a CancelToken for its scope
// (CancelScope); every long loop (photon tracing, the CPU gather, the path
// tracer) calls check_cancel() once per unit of work, which throws Cancelled
// once the token's deadline has passed or its stop flag was set. parallel_items (gi/parallel.hpp) hands the token to its
// worker threads and rethrows on the caller's thread. No token installed:
// check_cancel() costs one thread-local load and never throws.
#pragma once

#include <atomic>
#include <chrono>
#include <stdexcept>

namespace beamcast {

class Cancelled : public std::runtime_error {
 public:
  enum class Reason { kDeadline, kShutdown, kClientGone };
  Cancelled(Reason r, const char* what) : std::runtime_error(what), reason_(r) {}
  Reason reason() const { return reason_; }

 private:
  Reason reason_;
};

class CancelToken {
 public:
  using Clock = std::chrono::steady_clock;
  // `stop` (may be null): a flag that cancels the work once set (the
  // server's drain deadline); `alive` (may be null): a flag that cancels it
  // once cleared (the client's connection closed). Both must outlive the token.
  explicit CancelToken(Clock::time_point deadline = Clock::time_point::max(),
                       const std::atomic<bool>* stop = nullptr,
                       const std::atomic<bool>* alive = nullptr)
      : deadline_(deadline), stop_(stop), alive_(alive) {}

  Clock::time_point deadline() const { return deadline_; }
  bool expired() const { return deadline_ != Clock::time_point::max() && Clock::now() >= deadline_; }
  bool stopped() const { return stop_ && stop_->load(std::memory_order_relaxed); }
  bool client_gone() const { return alive_ && !alive_->load(std::memory_order_relaxed); }
  // Throws Cancelled if stopped, the client has gone or past the deadline.
  void check() const {
    if (stopped()) throw Cancelled(Cancelled::Reason::kShutdown, "cancelled: the server is stopping");
    if (client_gone()) throw Cancelled(Cancelled::Reason::kClientGone, "cancelled: the client has gone");
    if (expired()) throw Cancelled(Cancelled::Reason::kDeadline, "cancelled: past the deadline");
  }

 private:
  Clock::time_point deadline_;
  const std::atomic<bool>* stop_;
  const std::atomic<bool>* alive_;
};

namespace detail {
inline thread_local const CancelToken* t_cancel_token = nullptr;
}  // namespace detail

// The token of the work running on this thread (null: none).
inline const CancelToken* current_cancel_token() { return detail::t_cancel_token; }

// Installs `token` on this thread for the scope (null: none), restoring the previous one.
class CancelScope {
 public:
  explicit CancelScope(const CancelToken* token) : saved_(detail::t_cancel_token) {
    detail::t_cancel_token = token;
  }
  ~CancelScope() { detail::t_cancel_token = saved_; }
  CancelScope(const CancelScope&) = delete;
  CancelScope& operator=(const CancelScope&) = delete;

 private:
  const CancelToken* saved_;
};

// Throws Cancelled if the current work must stop (see above).
inline void check_cancel() {
  if (const CancelToken* t = detail::t_cancel_token) t->check();
}

}  // namespace beamcast
