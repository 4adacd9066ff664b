// Headless OpenGL 4.5 core context through EGL, with no window and no display:
// EGL_EXT_platform_device first (NVIDIA and other GPUs; pick the device by
// index), then Mesa's surfaceless platform (llvmpipe on machines without a GPU).
#pragma once

#include <memory>
#include <string>

namespace beamcast {

struct EglOptions {
  // Index into eglQueryDevicesEXT's list; -1: the environment variable
  // BEAMCAST_EGL_DEVICE if set, else try every device in order.
  int device_index = -1;
  // "auto" (device, then surfaceless), "device" or "surfaceless"; the
  // environment variable BEAMCAST_EGL_PLATFORM overrides "auto".
  std::string platform = "auto";
};

// Every GL call runs in a context that its caller owns: a renderer makes its
// own context current for the length of each entry point (EglContext::Current)
// and puts back what was current before, so renderers, bare contexts and
// threads can interleave without one issuing calls into another's namespace.
class EglContext {
 public:
  // Throws std::runtime_error with one line that says what was tried and why
  // each attempt failed. What was current on the calling thread before stays
  // current (the new context is made current only while it is set up).
  static std::unique_ptr<EglContext> create(const EglOptions& opts = {});
  // Releases this context if it is current on this thread (and nothing else).
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  // Scoped: makes `c` current on this thread and restores the display,
  // surfaces and context that were current before when it ends. Nests. While
  // one is alive, gl_check (render/gl_util.hpp) also checks that the
  // innermost guard's context is still the current one.
  class Current {
   public:
    explicit Current(const EglContext& c);
    ~Current();
    Current(const Current&) = delete;
    Current& operator=(const Current&) = delete;

   private:
    void* display_;  // what was current before
    void* draw_;
    void* read_;
    void* context_;
    const EglContext* outer_;  // the enclosing guard's context on this thread
  };

  // Whether this context is the one current on the calling thread.
  bool is_current() const;
  // The context the innermost Current on this thread made current (nullptr
  // outside any guard).
  static const EglContext* guarded();
  // Whether any context is current on the calling thread.
  static bool any_current();
  // e.g. "EGL device 0 (EGL_EXT_platform_device): NVIDIA H100 ... / 4.5.0 NVIDIA 550"
  const std::string& description() const { return description_; }
  const std::string& gl_renderer() const { return gl_renderer_; }
  // A debug context with KHR_debug output installed (render/gl_debug.hpp).
  bool gl_debug() const { return gl_debug_; }

 private:
  EglContext() = default;
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
  std::string description_;
  std::string gl_renderer_;
  bool gl_debug_ = false;
};

}  // namespace beamcast
