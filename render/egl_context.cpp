#include "render/egl_context.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>

#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/gl_debug.hpp"

namespace beamcast {
namespace {

#ifndef EGL_PLATFORM_SURFACELESS_MESA
#define EGL_PLATFORM_SURFACELESS_MESA 0x31DD
#endif

std::string egl_error_name(EGLint e) {
  switch (e) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    default: return "EGL error 0x" + [e] {
      char buf[16];
      std::snprintf(buf, sizeof buf, "%x", static_cast<unsigned>(e));
      return std::string(buf);
    }();
  }
}

// Whole-word match in a space-separated extension list.
bool has_extension(const std::string& list, const std::string& name) {
  std::size_t pos = 0;
  while ((pos = list.find(name, pos)) != std::string::npos) {
    const std::size_t end = pos + name.size();
    if ((pos == 0 || list[pos - 1] == ' ') && (end == list.size() || list[end] == ' ')) return true;
    pos = end;
  }
  return false;
}

struct Attempt {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
};

// Initializes `dpy` and creates a 4.5 core context on it, current on this
// thread. On failure returns an empty Attempt and sets `why`.
// `debug`: ask for a debug context (KHR_debug messages), else a plain one if refused.
Attempt try_display(EGLDisplay dpy, bool debug, std::string* why) {
  if (dpy == EGL_NO_DISPLAY) {
    *why = "no display (" + egl_error_name(eglGetError()) + ")";
    return {};
  }
  EGLint major = 0, minor = 0;
  if (!eglInitialize(dpy, &major, &minor)) {
    *why = "eglInitialize failed (" + egl_error_name(eglGetError()) + ")";
    return {};
  }
  auto fail = [&](const std::string& what) {
    *why = what + " (" + egl_error_name(eglGetError()) + ")";
    eglTerminate(dpy);
    return Attempt{};
  };
  const char* exts = eglQueryString(dpy, EGL_EXTENSIONS);
  if (!exts || !has_extension(exts, "EGL_KHR_surfaceless_context")) {
    *why = "EGL_KHR_surfaceless_context missing";
    eglTerminate(dpy);
    return {};
  }
  if (!eglBindAPI(EGL_OPENGL_API)) return fail("eglBindAPI(EGL_OPENGL_API) failed");
  const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint n = 0;
  // A config is needed for the context only; rendering goes to our own FBOs.
  if (!eglChooseConfig(dpy, config_attribs, &config, 1, &n) || n < 1) {
    // Some drivers offer no config without a surface type; KHR_no_config_context.
    config = EGL_NO_CONFIG_KHR;
  }
  // clang-format off
  EGLint ctx_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4,
                          EGL_CONTEXT_MINOR_VERSION, 5,
                          EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                          EGL_CONTEXT_OPENGL_DEBUG, debug ? EGL_TRUE : EGL_FALSE,
                          EGL_NONE};
  // clang-format on
  EGLContext ctx = eglCreateContext(dpy, config, EGL_NO_CONTEXT, ctx_attribs);
  if (ctx == EGL_NO_CONTEXT && debug) {
    ctx_attribs[7] = EGL_FALSE;  // EGL_CONTEXT_OPENGL_DEBUG
    ctx = eglCreateContext(dpy, config, EGL_NO_CONTEXT, ctx_attribs);
  }
  if (ctx == EGL_NO_CONTEXT) return fail("eglCreateContext(OpenGL 4.5 core) failed");
  if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
    eglDestroyContext(dpy, ctx);
    return fail("eglMakeCurrent(surfaceless) failed");
  }
  return {dpy, ctx};
}

int env_int(const char* name, int fallback) {
  const char* v = std::getenv(name);
  if (!v || !*v) return fallback;
  char* end = nullptr;
  const long x = std::strtol(v, &end, 10);
  if (*end != '\0') {
    throw std::runtime_error(std::string("EGL: ") + name + "='" + v + "' is not an integer");
  }
  return static_cast<int>(x);
}

// What is current on this thread, to put back later.
struct Bound {
  EGLDisplay display = eglGetCurrentDisplay();
  EGLSurface draw = eglGetCurrentSurface(EGL_DRAW);
  EGLSurface read = eglGetCurrentSurface(EGL_READ);
  EGLContext context = eglGetCurrentContext();
};

// Makes `b` current again; with no context before, releases `fallback`'s
// current context (a display is needed to release one).
void rebind(const Bound& b, EGLDisplay fallback) {
  if (b.context != EGL_NO_CONTEXT) {
    eglMakeCurrent(b.display, b.draw, b.read, b.context);
  } else if (eglGetCurrentContext() != EGL_NO_CONTEXT) {
    eglMakeCurrent(fallback, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
}

thread_local const EglContext* t_guarded = nullptr;

}  // namespace

std::unique_ptr<EglContext> EglContext::create(const EglOptions& opts) {
  std::string platform = opts.platform;
  if (const char* p = std::getenv("BEAMCAST_EGL_PLATFORM"); p && *p && platform == "auto") {
    platform = p;
  }
  if (platform != "auto" && platform != "device" && platform != "surfaceless") {
    throw std::runtime_error("EGL: unknown platform '" + platform +
                             "' (expected auto, device or surfaceless)");
  }
  const int device_index =
      opts.device_index >= 0 ? opts.device_index : env_int("BEAMCAST_EGL_DEVICE", -1);

  const bool debug = gl_debug_requested();
  const Bound before;
  std::vector<std::string> tried;
  Attempt got;
  std::string how;

  const char* client_exts = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  const std::string client = client_exts ? client_exts : "";
  auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));

  if (platform != "surfaceless") {
    auto query_devices =
        reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    if (!has_extension(client, "EGL_EXT_platform_device") || !query_devices || !get_platform_display) {
      tried.push_back("device platform: EGL_EXT_platform_device not offered");
    } else {
      EGLDeviceEXT devices[16];
      EGLint count = 0;
      if (!query_devices(16, devices, &count) || count == 0) {
        tried.push_back("device platform: no EGL devices");
      } else if (device_index >= count) {
        tried.push_back("device platform: device index " + std::to_string(device_index) +
                        " requested, " + std::to_string(count) + " present");
      } else {
        const int first = device_index >= 0 ? device_index : 0;
        const int last = device_index >= 0 ? device_index : count - 1;
        for (int i = first; i <= last && got.display == EGL_NO_DISPLAY; ++i) {
          std::string why;
          got = try_display(get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr),
                            debug, &why);
          if (got.display != EGL_NO_DISPLAY) {
            how = "EGL device " + std::to_string(i) + " (EGL_EXT_platform_device)";
          } else {
            tried.push_back("device " + std::to_string(i) + ": " + why);
          }
        }
      }
    }
  }
  if (got.display == EGL_NO_DISPLAY && platform != "device") {
    if (!has_extension(client, "EGL_MESA_platform_surfaceless") || !get_platform_display) {
      tried.push_back("surfaceless platform: EGL_MESA_platform_surfaceless not offered");
    } else {
      std::string why;
      got = try_display(
          get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr), debug,
          &why);
      if (got.display != EGL_NO_DISPLAY) {
        how = "Mesa surfaceless platform";
      } else {
        tried.push_back("surfaceless: " + why);
      }
    }
  }
  if (got.display == EGL_NO_DISPLAY) {
    std::string msg = "no headless OpenGL 4.5 core context: tried ";
    for (std::size_t i = 0; i < tried.size(); ++i) msg += (i ? "; " : "") + tried[i];
    throw std::runtime_error(msg);
  }

  std::unique_ptr<EglContext> c(new EglContext);
  c->display_ = got.display;
  c->context_ = got.context;
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  c->gl_renderer_ = renderer ? renderer : "?";
  c->description_ = how + ": " + c->gl_renderer_ + " / OpenGL " + (version ? version : "?");
  c->gl_debug_ = debug && install_gl_debug_output();
  rebind(before, got.display);
  return c;
}

EglContext::~EglContext() {
  if (display_) {
    if (is_current()) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (context_) eglDestroyContext(display_, context_);
    // No eglTerminate: the display of a device is shared by every context on
    // it (one per render worker), and terminating it would destroy theirs.
  }
}

bool EglContext::is_current() const { return context_ && eglGetCurrentContext() == context_; }

const EglContext* EglContext::guarded() { return t_guarded; }

bool EglContext::any_current() { return eglGetCurrentContext() != EGL_NO_CONTEXT; }

EglContext::Current::Current(const EglContext& c) : outer_(t_guarded) {
  const Bound b;
  display_ = b.display;
  draw_ = b.draw;
  read_ = b.read;
  context_ = b.context;
  if (b.context != c.context_ &&
      !eglMakeCurrent(c.display_, EGL_NO_SURFACE, EGL_NO_SURFACE, c.context_)) {
    throw std::runtime_error("eglMakeCurrent failed (" + egl_error_name(eglGetError()) + ")");
  }
  t_guarded = &c;
}

EglContext::Current::~Current() {
  const EglContext* mine = t_guarded;
  t_guarded = outer_;
  if (eglGetCurrentContext() != context_) {
    rebind(Bound{display_, draw_, read_, context_}, mine ? mine->display_ : EGL_NO_DISPLAY);
  }
}

}  // namespace beamcast
