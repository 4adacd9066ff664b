// QuadIndices (render/gl_util.hpp): quads drawn without instancing, in
// chunks of kChunk with a base vertex, reach the vertex shader as
// gl_VertexID >> 2 = the quad's index, each corner once.
#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "render/egl_context.hpp"
#include "render/gl_util.hpp"

namespace beamcast {
namespace {

constexpr int kWidth = 256;
constexpr int kHeight = 160;  // 40 960 pixels: room for two chunks and more

// Quad i covers pixel i (row-major) and writes i + 1 there.
const char* const kVertex = R"(#version 450 core
uniform ivec2 u_size;
flat out int v_quad;
void main() {
  int quad = gl_VertexID >> 2;
  vec2 corner = vec2(float(gl_VertexID & 1), float((gl_VertexID >> 1) & 1));
  vec2 pixel = vec2(float(quad % u_size.x), float(quad / u_size.x));
  vec2 window = pixel + 0.25 + 0.5 * corner;  // a half-pixel square about the centre
  gl_Position = vec4(window / vec2(u_size) * 2.0 - 1.0, 0.0, 1.0);
  v_quad = quad;
}
)";
const char* const kFragment = R"(#version 450 core
flat in int v_quad;
layout(location = 0) out float out_value;
void main() { out_value = float(v_quad + 1); }
)";

// The pixels after drawing quads first .. first + count - 1.
std::vector<float> draw_quads(GLsizei first, GLsizei count) {
  GlTexture target = make_texture_2d(GL_R32F, kWidth, kHeight);
  GLuint fbo = 0;
  glCreateFramebuffers(1, &fbo);
  GlFramebuffer framebuffer(fbo);
  glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, target.get(), 0);
  check_framebuffer(fbo, "quad test");
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, kWidth, kHeight);
  const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  glClearBufferfv(GL_COLOR, 0, zero);
  GlProgram program = build_program("quad_indices_test", kVertex, kFragment);
  glUseProgram(program.get());
  glUniform2i(glGetUniformLocation(program.get(), "u_size"), kWidth, kHeight);
  QuadIndices quads;
  quads.draw(first, count);
  std::vector<float> pixels(static_cast<std::size_t>(kWidth * kHeight));
  glGetTextureImage(target.get(), 0, GL_RED, GL_FLOAT, static_cast<GLsizei>(pixels.size() * 4),
                    pixels.data());
  gl_check("quad test");
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return pixels;
}

TEST(QuadIndices, EveryQuadOfEveryChunkReachesItsIndex) {
  auto ctx = EglContext::create();
  const EglContext::Current current(*ctx);
  // Two chunks and part of a third, starting past the first quad: the
  // base vertex of each chunk carries both the chunk and `first`.
  const GLsizei first = 37;
  const GLsizei count = 2 * QuadIndices::kChunk + 1000;
  ASSERT_LE(first + count, kWidth * kHeight);
  const std::vector<float> pixels = draw_quads(first, count);
  int wrong = 0;
  for (int i = 0; i < kWidth * kHeight; ++i) {
    const bool drawn = i >= first && i < first + count;
    const float want = drawn ? static_cast<float>(i + 1) : 0.0f;
    if (pixels[static_cast<std::size_t>(i)] != want) ++wrong;
  }
  EXPECT_EQ(wrong, 0);
}

TEST(QuadIndices, NoQuadsDrawNothing) {
  auto ctx = EglContext::create();
  const EglContext::Current current(*ctx);
  const std::vector<float> pixels = draw_quads(5, 0);
  for (const float v : pixels) ASSERT_EQ(v, 0.0f);
}

}  // namespace
}  // namespace beamcast
