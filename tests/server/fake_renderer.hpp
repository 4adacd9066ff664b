// A FrameRenderer without GL for the server's logic tests: each frame is one
// flat grey at the scene's bit depth, and the next render can be made to fail
// with a GL error or with another exception. It records the cameras of every
// render call in order, and can hold renders (hold_after) so that a test
// queues work behind a render in progress and then sees what the scheduler
// runs next, without timing anything. The GL integration tests
// (test_server.cpp, test_renderer_rebuild.cpp) keep the real renderer.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>
#include <stdexcept>
#include <utility>

#include "protocol/turns.hpp"
#include "render/gl_util.hpp"
#include "server/render_service.hpp"

namespace beamcast::test {

struct FakeRendererControl {
  std::atomic<int> created{0};          // renderers the factory has made
  std::atomic<bool> fail_other{false};  // next render throws std::runtime_error
  static constexpr std::uint16_t kGrey8 = 100;

  // Render calls beyond the first `n` wait (recorded, not returning) until
  // release().
  void hold_after(std::size_t n) {
    std::lock_guard lock(mu);
    allowed = n;
  }
  void release() {
    {
      std::lock_guard lock(mu);
      allowed = std::numeric_limits<std::size_t>::max();
    }
    cv.notify_all();
  }
  // Render call number `k` (1-based) waits until release_call(k); other
  // calls are not held by it.
  void hold_call(std::size_t k) {
    std::lock_guard lock(mu);
    held.insert(k);
  }
  void release_call(std::size_t k) {
    {
      std::lock_guard lock(mu);
      held.erase(k);
    }
    cv.notify_all();
  }
  std::size_t call_count() {
    std::lock_guard lock(mu);
    return calls.size();
  }
  // The camera names of each render call so far, in call order.
  std::vector<std::vector<std::string>> call_log() {
    std::lock_guard lock(mu);
    return calls;
  }
  // Render calls whose first camera's name starts with `prefix` take at
  // least `ms` (a costly render, as the scheduler measures it).
  void slow_renders(std::string prefix, int ms) {
    std::lock_guard lock(mu);
    slow_prefix = std::move(prefix);
    slow_ms = ms;
  }
  // Called by the renderer: records the call and waits while it is held.
  void enter(const std::vector<Camera>& cameras) {
    std::unique_lock lock(mu);
    std::vector<std::string> names;
    for (const Camera& c : cameras) names.push_back(c.name);
    const bool slow = !slow_prefix.empty() && !names.empty() && names[0].rfind(slow_prefix, 0) == 0;
    calls.push_back(std::move(names));
    const std::size_t me = calls.size();
    cv.wait(lock, [&] { return me <= allowed && held.count(me) == 0; });
    if (slow) {
      const int ms = slow_ms;
      lock.unlock();
      // In 1 ms steps, each followed by a turn point (protocol/turns.hpp)
      // as a real renderer's passes are; end_slow_renders() cuts it short.
      const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(ms);
      while (std::chrono::steady_clock::now() < end && !slow_end.load()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        turn_point([] {});
      }
    }
  }
  // Slow renders in progress and to come return at their next step.
  void end_slow_renders() { slow_end.store(true); }

  std::mutex mu;
  std::condition_variable cv;
  std::vector<std::vector<std::string>> calls;
  std::size_t allowed = std::numeric_limits<std::size_t>::max();
  std::set<std::size_t> held;
  std::string slow_prefix;
  int slow_ms = 0;
  std::atomic<bool> slow_end{false};
  // Renderers say they overlap (FrameRenderer::overlaps): the service then
  // finishes a slice after submitting the next, as with the GL renderer.
  std::atomic<bool> overlap{false};
};

class FakeFrameRenderer final : public FrameRenderer {
 public:
  explicit FakeFrameRenderer(std::shared_ptr<FakeRendererControl> control)
      : control_(std::move(control)) {
    control_->created.fetch_add(1);
  }
  std::string description() const override { return "fake renderer (no GL)"; }
  std::vector<FrameResult> render(const Scene& scene, const std::vector<Camera>& cameras) override {
    if (std::exchange(fail_gl_next_, false)) throw GlError("fake: injected GL error");
    if (control_->fail_other.exchange(false)) throw std::runtime_error("fake: not a GL error");
    control_->enter(cameras);
    std::vector<FrameResult> frames(cameras.size());
    for (std::size_t i = 0; i < cameras.size(); ++i) {
      Image& img = frames[i].image;
      img.width = cameras[i].width;
      img.height = cameras[i].height;
      img.bit_depth = scene.output.bit_depth;
      const std::uint16_t grey = img.bit_depth == 16 ? FakeRendererControl::kGrey8 * 257
                                                     : FakeRendererControl::kGrey8;
      img.rgb.assign(3 * static_cast<std::size_t>(img.width) * img.height, grey);
    }
    return frames;
  }
  void fail_next_render_for_test() override { fail_gl_next_ = true; }
  bool overlaps() const override { return control_->overlap.load(); }

 private:
  std::shared_ptr<FakeRendererControl> control_;
  bool fail_gl_next_ = false;
};

inline RendererFactory fake_renderer_factory(std::shared_ptr<FakeRendererControl> control) {
  return [control] { return std::make_unique<FakeFrameRenderer>(control); };
}

}  // namespace beamcast::test
