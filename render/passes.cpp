#include "render/passes.hpp"

#include "shaders/shader_sources.hpp"

namespace beamcast {

void FrameTargets::ensure(int w, int h, int bits) {
  if (w == width && h == height && bits == bit_depth) return;
  width = w;
  height = h;
  bit_depth = bits;
  hdr = make_texture_2d(GL_RGBA32F, w, h);
  view_depth = make_texture_2d(GL_R32F, w, h);
  depth = make_texture_2d(GL_DEPTH_COMPONENT32F, w, h);
  output = make_texture_2d(bits == 16 ? GL_RGBA16 : GL_RGBA8, w, h);
  GLuint ids[3];
  glCreateFramebuffers(3, ids);
  scene_fbo = GlFramebuffer(ids[0]);
  beam_fbo = GlFramebuffer(ids[1]);
  output_fbo = GlFramebuffer(ids[2]);
  glNamedFramebufferTexture(ids[0], GL_COLOR_ATTACHMENT0, hdr.get(), 0);
  glNamedFramebufferTexture(ids[0], GL_COLOR_ATTACHMENT1, view_depth.get(), 0);
  glNamedFramebufferTexture(ids[0], GL_DEPTH_ATTACHMENT, depth.get(), 0);
  const GLenum both[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glNamedFramebufferDrawBuffers(ids[0], 2, both);
  glNamedFramebufferTexture(ids[1], GL_COLOR_ATTACHMENT0, hdr.get(), 0);
  glNamedFramebufferTexture(ids[2], GL_COLOR_ATTACHMENT0, output.get(), 0);
  check_framebuffer(ids[0], "scene framebuffer");
  check_framebuffer(ids[1], "beam framebuffer");
  check_framebuffer(ids[2], "output framebuffer");
  gl_check("FrameTargets::ensure");
}

namespace {

// Occluders: rasterized triangles (boxes, meshes) and ray-traced planes and
// spheres, depth-tested together; writes shaded colour and view depth.
class SurfacePass final : public Pass {
 public:
  SurfacePass()
      : raster_(build_program("surface", assemble_shader({"common.glsl", "surface.vert"}),
                              assemble_shader({"common.glsl", "surface.frag"}))),
        analytic_(build_program("analytic_occluder",
                                assemble_shader({"common.glsl", "fullscreen.vert"}),
                                assemble_shader({"common.glsl", "analytic_occluder.frag"}))) {
    count_loc_ = glGetUniformLocation(analytic_.get(), "u_count");
  }
  const char* name() const override { return "surfaces"; }
  void execute(FrameContext& ctx) override {
    glBindFramebuffer(GL_FRAMEBUFFER, ctx.targets.scene_fbo.get());
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);  // reversed Z
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glDisable(GL_DEPTH_CLAMP);  // triangles are clipped by the near and far planes
    if (ctx.resources.triangle_vertex_count() > 0) {
      glUseProgram(raster_.get());
      glBindVertexArray(ctx.resources.triangle_vao());
      glDrawArrays(GL_TRIANGLES, 0, ctx.resources.triangle_vertex_count());
    }
    if (ctx.resources.analytic_count() > 0) {
      glUseProgram(analytic_.get());
      glUniform1i(count_loc_, ctx.resources.analytic_count());
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, ctx.resources.analytic_buffer());
      glBindVertexArray(ctx.empty_vao);
      glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    glDisable(GL_DEPTH_TEST);
    gl_check("surfaces pass");
  }

 private:
  GlProgram raster_;
  GlProgram analytic_;
  GLint count_loc_ = -1;
};

// Beams: additive energy from the line-integral tables, one instanced draw of
// box proxies, back faces only (see beam.vert).
class BeamPass final : public Pass {
 public:
  BeamPass()
      : program_(build_program("beam", assemble_shader({"common.glsl", "beam.vert"}),
                               assemble_shader({"common.glsl", "beam_math.glsl", "beam.frag"}))) {
    table_loc_ = glGetUniformLocation(program_.get(), "u_table_size");
    surfaces_loc_ = glGetUniformLocation(program_.get(), "u_has_surfaces");
    for (const char* name : {"u_warp_size", "u_method", "u_chord", "u_warped", "u_shader_filter",
                             "u_samples", "u_simpson", "u_near_parallel"}) {
      knob_loc_.push_back(glGetUniformLocation(program_.get(), name));
    }
  }
  const char* name() const override { return "beams"; }
  void execute(FrameContext& ctx) override {
    glBindFramebuffer(GL_FRAMEBUFFER, ctx.targets.beam_fbo.get());
    glUseProgram(program_.get());
    glUniform3i(table_loc_, ctx.resources.table_d(), ctx.resources.table_s(),
                ctx.resources.table_f());
    glUniform1i(surfaces_loc_, ctx.scene.occluders.empty() ? 0 : 1);
    const RenderSettings& rs = ctx.scene.render;
    const bool chord = rs.layout == TableLayout::kChord || rs.layout == TableLayout::kChordWarped;
    const bool warped = rs.layout == TableLayout::kWarped || rs.layout == TableLayout::kChordWarped;
    const int knobs[] = {ctx.resources.warp_size(),
                         static_cast<int>(rs.method),
                         chord ? 1 : 0,
                         warped ? 1 : 0,
                         rs.filter == TableFilter::kShader ? 1 : 0,
                         rs.samples,
                         rs.rule == MarchRule::kSimpson ? 1 : 0,
                         rs.near_parallel == NearParallel::kQuadrature ? 1 : 0};
    for (std::size_t k = 0; k < knob_loc_.size(); ++k) glUniform1i(knob_loc_[k], knobs[k]);
    glBindTextureUnit(0, ctx.resources.g_texture());
    glBindTextureUnit(1, ctx.resources.f_texture());
    glBindTextureUnit(2, ctx.targets.view_depth.get());
    glBindTextureUnit(3, ctx.resources.warp_texture());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, ctx.resources.beam_buffer());
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glBlendEquation(GL_FUNC_ADD);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_FRONT);
    glFrontFace(GL_CCW);
    glEnable(GL_DEPTH_CLAMP);  // proxies past the near or far plane still cover their pixels
    glDisable(GL_DEPTH_TEST);
    glBindVertexArray(ctx.empty_vao);
    glDrawArraysInstanced(GL_TRIANGLES, 0, 36, ctx.resources.beam_count());
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDisable(GL_DEPTH_CLAMP);
    gl_check("beams pass");
  }

 private:
  GlProgram program_;
  GLint table_loc_ = -1;
  GLint surfaces_loc_ = -1;
  std::vector<GLint> knob_loc_;  // same order as `knobs` in execute
};

// HDR -> display values in the output's bit depth.
class TonemapPass final : public Pass {
 public:
  TonemapPass()
      : program_(build_program("tonemap", assemble_shader({"common.glsl", "fullscreen.vert"}),
                               assemble_shader({"common.glsl", "tonemap.frag"}))) {
    exposure_loc_ = glGetUniformLocation(program_.get(), "u_exposure");
    curve_loc_ = glGetUniformLocation(program_.get(), "u_curve");
    levels_loc_ = glGetUniformLocation(program_.get(), "u_levels");
  }
  const char* name() const override { return "tonemap"; }
  void execute(FrameContext& ctx) override {
    glBindFramebuffer(GL_FRAMEBUFFER, ctx.targets.output_fbo.get());
    glUseProgram(program_.get());
    const OutputSettings& out = ctx.scene.output;
    glUniform1f(exposure_loc_, static_cast<float>(out.exposure));
    glUniform1i(curve_loc_, static_cast<int>(out.tone));
    glUniform1f(levels_loc_, out.bit_depth == 16 ? 65535.0f : 255.0f);
    glBindTextureUnit(0, ctx.targets.hdr.get());
    glBindVertexArray(ctx.empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    gl_check("tonemap pass");
  }

 private:
  GlProgram program_;
  GLint exposure_loc_ = -1, curve_loc_ = -1, levels_loc_ = -1;
};

}  // namespace

std::vector<std::unique_ptr<Pass>> make_passes() {
  std::vector<std::unique_ptr<Pass>> passes;
  passes.push_back(std::make_unique<SurfacePass>());
  passes.push_back(std::make_unique<BeamPass>());
  passes.push_back(std::make_unique<TonemapPass>());
  return passes;
}

}  // namespace beamcast
