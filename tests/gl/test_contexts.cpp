// Each renderer issues its GL calls in its own context (EglContext::Current),
// shadow cube maps filter across faces, draw validation names what is wrong,
// and beams whose proxy box holds the eye are drawn full-screen.
#define GL_GLEXT_PROTOTYPES
#include <EGL/egl.h>
#include <GL/glcorearb.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "protocol/camera.hpp"
#include "protocol/scene_json.hpp"
#include "protocol/turns.hpp"
#include "render/egl_context.hpp"
#include "render/gl_debug.hpp"
#include "render/gl_util.hpp"
#include "render/gl_validate.hpp"
#include "render/renderer.hpp"
#include "render/scene_resources.hpp"
#include "tests/common/examples.hpp"

namespace beamcast {
namespace {

// One triangle over the whole viewport (the draws of these tests).
const char* const kCoverVert = R"(#version 450 core
void main() { gl_Position = vec4(vec2(gl_VertexID & 1, gl_VertexID >> 1) * 4.0 - 1.0, 0.0, 1.0); }
)";


std::vector<std::uint16_t> frame(Renderer& r, const Scene& scene) {
  return r.render(scene).at(0).image.rgb;
}

// Two renderers on one thread, frames interleaved, a bare context created
// and destroyed between them, one renderer destroyed: every frame equals
// that renderer's first. Before each renderer made its own context current,
// A's second frame threw GL_INVALID_OPERATION (its names looked up in B's
// context), and after B was gone A rendered with no context at all.
TEST(Contexts, TwoRenderersInterleavedEqualTheirFramesAlone) {
  const Scene beams = small_example("paper_1set", 48);
  const Scene lit = small_example("cornell_box", 48);
  auto a = std::make_unique<Renderer>();
  const auto a_alone = frame(*a, beams);
  auto b = std::make_unique<Renderer>();
  const auto b_alone = frame(*b, lit);
  for (int round = 0; round < 2; ++round) {
    EXPECT_EQ(frame(*a, beams), a_alone) << "round " << round;
    { auto bare = EglContext::create(); }
    EXPECT_EQ(frame(*b, lit), b_alone) << "round " << round;
    auto bare = EglContext::create();
    EXPECT_EQ(frame(*a, beams), a_alone) << "round " << round << ", a bare context alive";
  }
  b.reset();
  EXPECT_EQ(frame(*a, beams), a_alone) << "after the other renderer was destroyed";
}

// Turns inside a frame (protocol/turns.hpp), as the server's render worker
// takes them: renderer A renders the caustic Cornell box (its specular rays
// on the CPU, in row blocks) with a hook that is always due and renders a
// beam frame on renderer B at every turn. A's frame equals A's frame alone
// and every B frame equals B's alone, bit for bit: a turn leaves the other
// renderer's context, targets and half-done frame as they were. The turns
// come between passes and between the specular pass's row blocks (48 rows
// in blocks that start at the core count and grow at most 4x a block: at
// least 3 blocks, so 2 turns inside that pass).
TEST(Contexts, TurnsInsideAFrameLeaveBothFramesAsAlone) {
  Scene caustic = small_example("cornell_caustic", 48);
  caustic.gi.specular_tracer = SpecularTracer::kCpu;
  const Scene beams = small_example("paper_1set", 32);
  Renderer a, b;
  const auto a_alone = frame(a, caustic);
  const auto b_alone = frame(b, beams);
  struct Hook final : TurnHook {
    Renderer* other = nullptr;
    const Scene* scene = nullptr;
    std::vector<std::vector<std::uint16_t>> frames;
    bool due() override { return true; }
    void take() override { frames.push_back(frame(*other, *scene)); }
  } hook;
  hook.other = &b;
  hook.scene = &beams;
  const double before = turn_ms_taken();
  std::vector<std::uint16_t> a_turned;
  {
    const TurnScope scope(&hook);
    a_turned = frame(a, caustic);
  }
  EXPECT_EQ(a_turned, a_alone) << "A's frame changed by the turns inside it";
  // Passes - 1 boundaries plus the specular pass's 2.
  EXPECT_GE(hook.frames.size(), 4u);
  for (std::size_t k = 0; k < hook.frames.size(); ++k) {
    EXPECT_EQ(hook.frames[k], b_alone) << "B's frame in turn " << k;
  }
  EXPECT_GT(turn_ms_taken(), before);
  EXPECT_EQ(frame(a, caustic), a_alone) << "after the turns";
}

// A context the caller has current stays current across a render, and a
// renderer made elsewhere renders right beside it.
TEST(Contexts, RenderRestoresTheCallersContext) {
  const Scene beams = small_example("paper_1set", 32);
  Renderer r;
  const auto alone = frame(r, beams);
  auto mine = EglContext::create();
  EXPECT_FALSE(mine->is_current()) << "create() leaves the thread's context as it was";
  const EglContext::Current current(*mine);
  EXPECT_TRUE(mine->is_current());
  EXPECT_EQ(frame(r, beams), alone);
  EXPECT_TRUE(mine->is_current()) << "the render put the caller's context back";
  EXPECT_EQ(EglContext::guarded(), mine.get());
}

// gl_check names the fault when the context current is not the one the
// innermost guard made current (switched behind its back), or when none is.
TEST(Contexts, GlCheckRefusesAForeignOrMissingContext) {
  ASSERT_FALSE(EglContext::any_current()) << "a test left a context current";
  EXPECT_THROW(gl_check("nothing current"), GlError);
  auto owner = EglContext::create();
  auto other = EglContext::create();
  EGLContext other_handle = EGL_NO_CONTEXT;
  {
    const EglContext::Current inner(*other);
    other_handle = eglGetCurrentContext();
  }
  const EglContext::Current current(*owner);
  gl_check("owner current");
  EGLContext owner_handle = eglGetCurrentContext();
  EGLDisplay display = eglGetCurrentDisplay();
  ASSERT_TRUE(eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, other_handle));
  try {
    gl_check("behind the guard's back");
    ADD_FAILURE() << "gl_check did not notice the foreign context";
  } catch (const GlError& e) {
    EXPECT_NE(std::string(e.what()).find("another context"), std::string::npos) << e.what();
  }
  ASSERT_TRUE(eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, owner_handle));
  gl_check("owner current again");
}

// A 1-cube shadow array, +X face at depth 0, +Y face at depth 1 (written
// the way the direct pass writes its maps: a framebuffer clear of each
// layer-face), looked up in a fragment shader at the +X face's edge toward
// +Y with reference 0.5: a seamless filter gives the +Y texels about half
// the weight (0.498 at t = 0.0005 of a 4-texel face), so about half the
// samples pass; without it the +X face's own edge texels (clamped, or the
// far edge under GL_REPEAT) all fail: 0.
TEST(ShadowCubes, FilteringAcrossAFaceSeamUsesTheNeighbouringFace) {
  auto ctx = EglContext::create();
  const EglContext::Current current(*ctx);
  constexpr GLsizei kSize = 4;
  GlTexture cubes = make_shadow_cube_array(kSize, 1);
  GLuint id = 0;
  glCreateFramebuffers(1, &id);
  GlFramebuffer depth_fbo(id);
  glNamedFramebufferDrawBuffer(id, GL_NONE);
  for (int face = 0; face < 6; ++face) {
    const float depth = face == 2 ? 1.0f : 0.0f;  // face 2: +Y
    glNamedFramebufferTextureLayer(id, GL_DEPTH_ATTACHMENT, cubes.get(), 0, face);
    glClearNamedFramebufferfv(id, GL_DEPTH, 0, &depth);
  }
  GlTexture result = make_texture_2d(GL_R32F, 1, 1);
  glCreateFramebuffers(1, &id);
  GlFramebuffer fbo(id);
  glNamedFramebufferTexture(id, GL_COLOR_ATTACHMENT0, result.get(), 0);
  const std::string frag = R"(#version 450 core
layout(binding = 0) uniform samplerCubeArrayShadow u_cubes;
uniform vec3 u_dir;
layout(location = 0) out float o;
void main() { o = texture(u_cubes, vec4(u_dir, 0.0), 0.5); }
)";
  GlProgram program = build_program("cube_seam_test", kCoverVert, frag);
  GLuint vao = 0;
  glCreateVertexArrays(1, &vao);
  GlVertexArray empty(vao);
  glUseProgram(program.get());
  glBindVertexArray(vao);
  glBindTextureUnit(0, cubes.get());
  glBindFramebuffer(GL_FRAMEBUFFER, id);
  glViewport(0, 0, 1, 1);
  auto lookup = [&](float x, float y, float z) {
    glUniform3f(glGetUniformLocation(program.get(), "u_dir"), x, y, z);
    draw_arrays(GL_TRIANGLES, 0, 3);
    float v = -1.0f;
    glGetTextureImage(result.get(), 0, GL_RED, GL_FLOAT, sizeof v, &v);
    gl_check("cube seam lookup");
    return v;
  };
  EXPECT_EQ(lookup(1.0f, 0.0f, 0.0f), 0.0f) << "the +X face's middle";
  EXPECT_EQ(lookup(0.0f, 1.0f, 0.0f), 1.0f) << "the +Y face's middle";
  const float seam = lookup(1.0f, 0.999f, 0.0f);
  EXPECT_GT(seam, 0.25f) << "the +Y face's texels take no part: seamless filtering is off";
  EXPECT_LT(seam, 0.75f);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

// Draw validation on planted defects: each throws naming the pass and unit
// (or the framebuffer) before the draw reaches the driver.
class Validation : public ::testing::Test {
 protected:
  void SetUp() override {
    ctx_ = EglContext::create();
    current_ = std::make_unique<EglContext::Current>(*ctx_);
    was_ = gl_validation_enabled();
    set_gl_validation(true);
    target_ = make_texture_2d(GL_R32F, 4, 4);
    GLuint id = 0;
    glCreateFramebuffers(1, &id);
    fbo_ = GlFramebuffer(id);
    glNamedFramebufferTexture(id, GL_COLOR_ATTACHMENT0, target_.get(), 0);
    glCreateVertexArrays(1, &id);
    vao_ = GlVertexArray(id);
      const std::string frag = R"(#version 450 core
layout(binding = 3) uniform sampler2D u_input;
layout(location = 0) out float o;
void main() { o = texture(u_input, vec2(0.5)).r; }
)";
    program_ = build_program("validation_test", kCoverVert, frag);
    glUseProgram(program_.get());
    glBindVertexArray(vao_.get());
    glViewport(0, 0, 4, 4);
  }
  void TearDown() override {
    set_gl_validation(was_);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    take_gl_debug_errors();
  }
  // The message of the GlError the draw threw ("" if none).
  std::string draw_error() {
    const GlPassLabel label(pass_);
    try {
      draw_arrays(GL_TRIANGLES, 0, 3);
    } catch (const GlError& e) {
      return e.what();
    }
    return "";
  }
  std::unique_ptr<EglContext> ctx_;
  std::unique_ptr<EglContext::Current> current_;
  bool was_ = false;
  const std::string pass_ = "planted";
  GlTexture target_;
  GlFramebuffer fbo_;
  GlVertexArray vao_;
  GlProgram program_;
};

TEST_F(Validation, ACompleteDrawPasses) {
  GlTexture input = make_texture_2d(GL_R32F, 1, 1);
  glBindTextureUnit(3, input.get());
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
  EXPECT_EQ(draw_error(), "");
  gl_check("complete draw");
}

TEST_F(Validation, ASamplerLeftUnboundNamesPassProgramAndUnit) {
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
  const std::string e = draw_error();
  EXPECT_NE(e.find("planted pass"), std::string::npos) << e;
  EXPECT_NE(e.find("program 'validation_test'"), std::string::npos) << e;
  EXPECT_NE(e.find("unit 3 (sampler2D u_input): no texture"), std::string::npos) << e;
}

TEST_F(Validation, AStaleNameFromAnotherContextLeavesTheUnitEmpty) {
  GLuint stale = 0;
  {
    auto other = EglContext::create();
    const EglContext::Current inner(*other);
    GlTexture foreign = make_texture_2d(GL_R32F, 1, 1);
    stale = foreign.get() + 100;  // a name this context never made
  }
  std::vector<GlDebugMessage> seen;
  auto previous = set_gl_debug_sink([&](const GlDebugMessage& m) { seen.push_back(m); });
  glBindTextureUnit(3, stale);
  set_gl_debug_sink(previous);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_INVALID_OPERATION));
  take_gl_debug_errors();
  if (ctx_->gl_debug()) {
    ASSERT_FALSE(seen.empty());
    EXPECT_EQ(seen.front().type, "error");
  }
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
  const std::string e = draw_error();
  EXPECT_NE(e.find("planted pass"), std::string::npos) << e;
  EXPECT_NE(e.find("unit 3"), std::string::npos) << e;
}

TEST_F(Validation, AnIncompleteFramebufferNamesPassAndStatus) {
  GlTexture input = make_texture_2d(GL_R32F, 1, 1);
  glBindTextureUnit(3, input.get());
  GLuint id = 0;
  glCreateFramebuffers(1, &id);
  GlFramebuffer empty(id);  // no attachment
  glBindFramebuffer(GL_FRAMEBUFFER, id);
  const std::string e = draw_error();
  EXPECT_NE(e.find("planted pass"), std::string::npos) << e;
  EXPECT_NE(e.find("is not complete"), std::string::npos) << e;
}

TEST_F(Validation, AShadowSamplerNeedsDepthComparison) {
  const std::string frag = R"(#version 450 core
layout(binding = 5) uniform sampler2DShadow u_depth;
layout(location = 0) out float o;
void main() { o = texture(u_depth, vec3(0.5, 0.5, 0.5)); }
)";
  GlProgram shadow = build_program("shadow_validation_test", kCoverVert, frag);
  glUseProgram(shadow.get());
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &id);
  GlTexture depth(id);
  glTextureStorage2D(id, 1, GL_DEPTH_COMPONENT32F, 1, 1);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glBindTextureUnit(5, id);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
  const std::string e = draw_error();
  EXPECT_NE(e.find("unit 5 (sampler2DShadow u_depth): texture"), std::string::npos) << e;
  EXPECT_NE(e.find("no depth comparison"), std::string::npos) << e;
}

// The full-screen rule in double: a perspective eye inside a proxy box or
// within twice the near plane's corner distance of it; never orthographic.
TEST(BeamProxy, EyeInsideOrNearTheBoxTakesTheFullScreenPath) {
  Camera cam;
  cam.width = cam.height = 8;
  cam.fov_y_deg = 60.0;
  cam.near_plane = 0.01;
  const CameraBasis basis = camera_basis(cam);
  BeamGpu sphere;  // centre at p0 (camera-relative), radius 1
  sphere.p0 = {0.5, -0.5, 0.2};
  EXPECT_TRUE(beam_proxy_full_screen(sphere, 1.0, cam, basis)) << "inside";
  sphere.p0 = {0.0, 0.0, -1.01};  // the box's face 0.01 away
  EXPECT_TRUE(beam_proxy_full_screen(sphere, 1.0, cam, basis)) << "within the near distance";
  sphere.p0 = {0.0, 0.0, -3.0};
  EXPECT_FALSE(beam_proxy_full_screen(sphere, 1.0, cam, basis)) << "2 radii away";
  BeamGpu capsule;  // axis from p0 along +x, length 10, caps at both ends
  capsule.p0 = {-5.0, 0.3, 0.0};
  capsule.axis = {1.0, 0.0, 0.0};
  capsule.length = 10.0;
  capsule.caps_kind = {1.0, 1.0, 1.0};
  EXPECT_TRUE(beam_proxy_full_screen(capsule, 0.5, cam, basis)) << "inside, off the axis";
  capsule.p0 = {-5.0, 2.0, 0.0};
  EXPECT_FALSE(beam_proxy_full_screen(capsule, 0.5, cam, basis)) << "beside it";
  capsule.p0 = {0.6, 0.0, 0.0};  // the eye 0.1 past the p0 cap's end
  EXPECT_FALSE(beam_proxy_full_screen(capsule, 0.5, cam, basis)) << "past the cap";
  capsule.p0 = {0.5, 0.0, 0.0};
  EXPECT_TRUE(beam_proxy_full_screen(capsule, 0.5, cam, basis)) << "on the cap's end";
  Camera ortho = cam;
  ortho.projection = Projection::kOrthographic;
  sphere.p0 = {0.0, 0.0, 0.0};
  EXPECT_FALSE(beam_proxy_full_screen(sphere, 1.0, ortho, camera_basis(ortho)));
}

}  // namespace
}  // namespace beamcast
