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

class EglContext {
 public:
  // Throws std::runtime_error with one line that says what was tried and why
  // each attempt failed.
  static std::unique_ptr<EglContext> create(const EglOptions& opts = {});
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  // Binds the context to the calling thread (a context is current on one
  // thread at a time; the render worker that owns it calls this once).
  void make_current();
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
