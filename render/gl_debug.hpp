// KHR_debug output: in a debug context (Debug builds, -DBEAMCAST_GL_DEBUG=ON,
// or BEAMCAST_GL_DEBUG=1 in the environment) the driver reports misuse, errors
// and performance warnings as messages. They go to stderr (or a test's sink);
// a message of type error or undefined behaviour fails the next gl_check on
// that thread.
#pragma once

#include <functional>
#include <string>

namespace beamcast {

struct GlDebugMessage {
  std::string source;    // "api", "shader compiler", ...
  std::string type;      // "error", "performance", "undefined behavior", ...
  std::string severity;  // "high", "medium", "low", "notification"
  unsigned id = 0;
  std::string text;
};

// "GL debug [high error api #1282]: glBindBuffer(...)".
std::string format_gl_debug_message(const GlDebugMessage& m);

// Whether new contexts are debug contexts: the environment variable
// BEAMCAST_GL_DEBUG ("0" or "1") if set, else the build's default (ON in
// Debug builds and with the CMake option BEAMCAST_GL_DEBUG).
bool gl_debug_requested();

// Receives every message of this process's debug contexts; the default (an
// empty function) prints all but notifications to stderr. Returns the previous
// sink. For tests: install, provoke, restore.
using GlDebugSink = std::function<void(const GlDebugMessage&)>;
GlDebugSink set_gl_debug_sink(GlDebugSink sink);

// On the current context: if it is a debug context, enables synchronous debug
// output into the sink. Returns whether it did.
bool install_gl_debug_output();

// Error and undefined-behaviour messages seen on this thread since the last call, joined with
// "; " (empty if none); clears them. gl_check() throws when this is not empty.
std::string take_gl_debug_errors();

}  // namespace beamcast
