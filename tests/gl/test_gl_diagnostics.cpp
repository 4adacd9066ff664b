// GL diagnostics on llvmpipe: KHR_debug messages from a debug context reach
// the sink and fail gl_check; a shader compile error names file and line.
#define GL_GLEXT_PROTOTYPES  // glEnable, to misuse GL on purpose
#include <GL/glcorearb.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "render/egl_context.hpp"
#include "render/gl_debug.hpp"
#include "render/gl_util.hpp"
#include "shaders/shader_sources.hpp"

namespace beamcast {
namespace {

// A context with BEAMCAST_GL_DEBUG set to `value` while it is created (the
// variable put back as it was: the test main sets it for the whole binary).
std::unique_ptr<EglContext> context_with_debug(const char* value) {
  const char* was = std::getenv("BEAMCAST_GL_DEBUG");
  const std::string saved = was ? was : "";
  setenv("BEAMCAST_GL_DEBUG", value, 1);
  auto ctx = EglContext::create();
  if (was) {
    setenv("BEAMCAST_GL_DEBUG", saved.c_str(), 1);
  } else {
    unsetenv("BEAMCAST_GL_DEBUG");
  }
  return ctx;
}

// A debug context, whatever the build's default.
std::unique_ptr<EglContext> debug_context() { return context_with_debug("1"); }

TEST(GlDiagnostics, DebugContextReportsMisuseToTheSink) {
  auto ctx = debug_context();
  const EglContext::Current current(*ctx);
  ASSERT_TRUE(ctx->gl_debug()) << "no debug context with KHR_debug on " << ctx->description();
  std::vector<GlDebugMessage> got;
  auto previous = set_gl_debug_sink([&](const GlDebugMessage& m) { got.push_back(m); });
  glEnable(0xDEAD);  // not a capability: GL_INVALID_ENUM
  set_gl_debug_sink(previous);
  ASSERT_FALSE(got.empty());
  EXPECT_EQ(got.front().type, "error");
  EXPECT_EQ(got.front().severity, "high");
  EXPECT_NE(format_gl_debug_message(got.front()).find("GL debug [high error api"),
            std::string::npos)
      << format_gl_debug_message(got.front());
  // gl_check reports the GL error and the driver's explanation.
  try {
    gl_check("glEnable");
    FAIL() << "gl_check did not throw";
  } catch (const GlError& e) {
    EXPECT_NE(std::string(e.what()).find("GL_INVALID_ENUM"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("GL debug [high error"), std::string::npos) << e.what();
  }
  EXPECT_EQ(take_gl_debug_errors(), "");  // consumed by gl_check
}

TEST(GlDiagnostics, PlainContextWithoutDebugOutput) {
  auto ctx = context_with_debug("0");
  const EglContext::Current current(*ctx);
  EXPECT_FALSE(ctx->gl_debug());
  glEnable(0xDEAD);
  EXPECT_EQ(take_gl_debug_errors(), "");
  EXPECT_THROW(gl_check("glEnable"), GlError);  // glGetError still reports it
}

TEST(GlDiagnostics, ShaderCompileErrorNamesFileAndLine) {
  auto ctx = debug_context();
  const EglContext::Current current(*ctx);
  auto previous = set_gl_debug_sink([](const GlDebugMessage&) {});  // expected errors
  const std::string vert = assemble_shader({"common.glsl", "fullscreen.vert"});
  const std::string frag = assemble_shader_text(
      {{"common.glsl", shader_text("common.glsl")},
       {"broken.frag", "out vec4 o;\nvoid main() {\n  o = vec4(undefined_name);\n}"}});
  std::string what;
  try {
    build_program("broken", vert, frag);
  } catch (const GlError& e) {
    what = e.what();
  }
  set_gl_debug_sink(previous);
  take_gl_debug_errors();
  EXPECT_NE(what.find("compiling fragment shader of program 'broken' failed"), std::string::npos)
      << what;
  // Mesa's log "1:3(11): error: ..." becomes "broken.frag:3(11): error: ...";
  // NVIDIA's "1(3) : error C1503: ..." becomes "broken.frag(3) : error ...".
  EXPECT_TRUE(what.find("broken.frag:3(") != std::string::npos ||
              what.find("broken.frag(3)") != std::string::npos)
      << what;
  EXPECT_NE(what.find("broken.frag:   3 |   o = vec4(undefined_name);"), std::string::npos) << what;
  EXPECT_NE(what.find("common.glsl:   1 | "), std::string::npos) << what;
}

}  // namespace
}  // namespace beamcast
