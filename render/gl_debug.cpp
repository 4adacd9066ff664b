#include "render/gl_debug.hpp"

#include <GL/glcorearb.h>

#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <utility>

namespace beamcast {

namespace {

#ifdef BEAMCAST_GL_DEBUG_DEFAULT
constexpr bool kBuildDefault = true;
#else
constexpr bool kBuildDefault = false;
#endif

std::mutex g_sink_mutex;
GlDebugSink g_sink;
// Output is synchronous, so a message arrives on the thread that made the call.
thread_local std::string t_errors;

struct EnumName {
  GLenum value;
  const char* name;
};

// The name of `value` in `table`, else `fallback`.
template <std::size_t N>
const char* name_of(GLenum value, const EnumName (&table)[N], const char* fallback) {
  for (const EnumName& e : table) {
    if (e.value == value) return e.name;
  }
  return fallback;
}

constexpr EnumName kSources[] = {{GL_DEBUG_SOURCE_API, "api"},
                                 {GL_DEBUG_SOURCE_WINDOW_SYSTEM, "window system"},
                                 {GL_DEBUG_SOURCE_SHADER_COMPILER, "shader compiler"},
                                 {GL_DEBUG_SOURCE_THIRD_PARTY, "third party"},
                                 {GL_DEBUG_SOURCE_APPLICATION, "application"}};
constexpr EnumName kTypes[] = {{GL_DEBUG_TYPE_ERROR, "error"},
                               {GL_DEBUG_TYPE_DEPRECATED_BEHAVIOR, "deprecated"},
                               {GL_DEBUG_TYPE_UNDEFINED_BEHAVIOR, "undefined behavior"},
                               {GL_DEBUG_TYPE_PORTABILITY, "portability"},
                               {GL_DEBUG_TYPE_PERFORMANCE, "performance"},
                               {GL_DEBUG_TYPE_MARKER, "marker"}};
constexpr EnumName kSeverities[] = {{GL_DEBUG_SEVERITY_HIGH, "high"},
                                    {GL_DEBUG_SEVERITY_MEDIUM, "medium"},
                                    {GL_DEBUG_SEVERITY_LOW, "low"}};

void APIENTRY on_message(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei length,
                         const GLchar* text, const void* /*user*/) {
  GlDebugMessage m{name_of(source, kSources, "other"), name_of(type, kTypes, "other"),
                   name_of(severity, kSeverities, "notification"), id,
                   length >= 0 ? std::string(text, static_cast<std::size_t>(length)) : text};
  // Errors and undefined behaviour, whatever their severity; not the
  // compiler's warnings (Mesa sends those at high severity, type "other").
  if (type == GL_DEBUG_TYPE_ERROR || type == GL_DEBUG_TYPE_UNDEFINED_BEHAVIOR) {
    t_errors += (t_errors.empty() ? "" : "; ") + format_gl_debug_message(m);
  }
  std::lock_guard lock(g_sink_mutex);
  if (g_sink) {
    g_sink(m);
  } else if (severity != GL_DEBUG_SEVERITY_NOTIFICATION) {
    std::fprintf(stderr, "beamcast: %s\n", format_gl_debug_message(m).c_str());
  }
}

}  // namespace

std::string format_gl_debug_message(const GlDebugMessage& m) {
  return "GL debug [" + m.severity + " " + m.type + " " + m.source + " #" + std::to_string(m.id) +
         "]: " + m.text;
}

bool gl_debug_requested() {
  const char* v = std::getenv("BEAMCAST_GL_DEBUG");
  if (v && *v) return std::string(v) != "0";
  return kBuildDefault;
}

GlDebugSink set_gl_debug_sink(GlDebugSink sink) {
  std::lock_guard lock(g_sink_mutex);
  return std::exchange(g_sink, std::move(sink));
}

bool install_gl_debug_output() {
  GLint flags = 0;
  glGetIntegerv(GL_CONTEXT_FLAGS, &flags);
  if (!(flags & GL_CONTEXT_FLAG_DEBUG_BIT)) return false;
  glEnable(GL_DEBUG_OUTPUT);
  // Synchronous: the message arrives inside the offending call, on its thread.
  glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
  glDebugMessageCallback(on_message, nullptr);
  glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, nullptr, GL_TRUE);
  return true;
}

std::string take_gl_debug_errors() { return std::exchange(t_errors, std::string()); }

}  // namespace beamcast
