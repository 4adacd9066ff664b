// Turns inside a long render (issue 43, "fair shares"): a render that has
// run for a while lets waiting cheap renders run on the same thread between
// its steps, so one costly frame does not hold a render worker for its whole
// length.
//
// The thread that renders installs a TurnHook for the scope (TurnScope; the
// server's render service does, protocol/ only defines the seam). Long
// renders call turn_point() at points where their own state survives another
// render running in between: between the passes of a frame, between blocks
// of rows of a CPU pass. No hook installed: turn_point() costs one
// thread-local load. A turn never nests: while the hook's take() runs, no
// hook is installed, so the render it runs cannot take turns itself.
#pragma once

#include <chrono>

namespace beamcast {

class TurnHook {
 public:
  virtual ~TurnHook() = default;
  // Whether a turn should be taken now (this render has had its share and
  // other work is waiting). Cheap; called at every turn point.
  virtual bool due() = 0;
  // Runs the waiting work (on this thread), then returns to the caller.
  virtual void take() = 0;
};

namespace detail {
inline thread_local TurnHook* t_turn_hook = nullptr;
inline thread_local double t_turn_ms = 0.0;
}  // namespace detail

// Whether turns may be taken on this thread now.
inline bool turn_hook_installed() { return detail::t_turn_hook != nullptr; }

// Wall time (ms) this thread has spent in turns so far: a render reads it
// before and after a stretch to take what it gave to others out of its own
// times.
inline double turn_ms_taken() { return detail::t_turn_ms; }

// Installs `hook` on this thread for the scope (null: none), restoring the previous one.
class TurnScope {
 public:
  explicit TurnScope(TurnHook* hook) : saved_(detail::t_turn_hook) { detail::t_turn_hook = hook; }
  ~TurnScope() { detail::t_turn_hook = saved_; }
  TurnScope(const TurnScope&) = delete;
  TurnScope& operator=(const TurnScope&) = delete;

 private:
  TurnHook* saved_;
};

// A point where the render running on this thread may give a turn. `before`
// runs only when the turn is taken, first: it completes what the render has
// queued so far (a GL render waits for its commands, so their time is its
// own, not the turn's). Returns whether a turn was taken; a GL caller's
// context is current again on return (render/egl_context.hpp's guards
// restore it), everything else it holds is untouched.
template <class Before>
bool turn_point(Before&& before) {
  TurnHook* hook = detail::t_turn_hook;
  if (hook == nullptr || !hook->due()) return false;
  before();
  const auto t0 = std::chrono::steady_clock::now();
  {
    const TurnScope none(nullptr);
    hook->take();
  }
  detail::t_turn_ms +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return true;
}

}  // namespace beamcast
