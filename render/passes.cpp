#include "render/passes.hpp"

#include <string>
#include <utility>

#include "shaders/shader_sources.hpp"

namespace beamcast {

void FrameTargets::ensure(int w, int h, int bits, int layer_count) {
  if (w == width && h == height && bits == bit_depth && layer_count == layers) return;
  width = w;
  height = h;
  bit_depth = bits;
  layers = layer_count;
  auto make = [&](GLenum format) {
    if (layer_count == 0) return make_texture_2d(format, w, h);
    GLuint id = 0;
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &id);
    glTextureStorage3D(id, 1, format, w, h, layer_count);
    glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    return GlTexture(id);
  };
  hdr = make(GL_RGBA32F);
  view_depth = make(GL_R32F);
  depth = make(GL_DEPTH_COMPONENT32F);
  output = make(bits == 16 ? GL_RGBA16 : GL_RGBA8);
  GLuint ids[3];
  glCreateFramebuffers(3, ids);
  scene_fbo = GlFramebuffer(ids[0]);
  beam_fbo = GlFramebuffer(ids[1]);
  output_fbo = GlFramebuffer(ids[2]);
  // glNamedFramebufferTexture attaches every layer of an array texture (layered).
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

// A program in its per-camera and its multi-view variant (the latter built on
// first use; see shaders/multiview*.glsl).
class ProgramPair {
 public:
  ProgramPair(std::string name, std::vector<std::string_view> vert,
              std::vector<std::string_view> frag)
      : name_(std::move(name)), vert_(std::move(vert)), frag_(std::move(frag)) {
    single_ = build_program(name_, assemble_shader(vert_), assemble_shader(frag_));
  }
  GLuint get(bool multiview) {
    if (!multiview) return single_.get();
    if (!multi_) {
      std::vector<std::string_view> v = vert_, f = frag_;
      v.insert(v.begin(), "multiview_vertex.glsl");
      f.insert(f.begin(), "multiview.glsl");
      multi_ = build_program(name_ + "_multiview", assemble_shader(v), assemble_shader(f));
    }
    return multi_.get();
  }
  GLint uniform(bool multiview, const char* name) {
    return glGetUniformLocation(get(multiview), name);
  }

 private:
  std::string name_;
  std::vector<std::string_view> vert_, frag_;
  GlProgram single_, multi_;
};

// Instances per draw: one per view in a multi-view batch.
GLsizei instances(const FrameContext& ctx) { return ctx.views > 0 ? ctx.views : 1; }

// Occluders: rasterized triangles (boxes, meshes) and ray-traced planes and
// spheres, depth-tested together; writes shaded colour and view depth.
class SurfacePass final : public Pass {
 public:
  SurfacePass()
      : raster_("surface", {"common.glsl", "surface.vert"}, {"common.glsl", "surface.frag"}),
        analytic_("analytic_occluder", {"common.glsl", "fullscreen.vert"},
                  {"common.glsl", "analytic_occluder.frag"}) {}
  const char* name() const override { return "surfaces"; }
  void execute(FrameContext& ctx) override {
    const bool multi = ctx.views > 0;
    glBindFramebuffer(GL_FRAMEBUFFER, ctx.targets.scene_fbo.get());
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);  // reversed Z
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glDisable(GL_DEPTH_CLAMP);  // triangles are clipped by the near and far planes
    if (ctx.resources.triangle_vertex_count() > 0) {
      glUseProgram(raster_.get(multi));
      glBindVertexArray(ctx.resources.triangle_vao());
      glDrawArraysInstanced(GL_TRIANGLES, 0, ctx.resources.triangle_vertex_count(),
                            instances(ctx));
    }
    if (ctx.resources.analytic_count() > 0) {
      glUseProgram(analytic_.get(multi));
      glUniform1i(analytic_.uniform(multi, "u_count"), ctx.resources.analytic_count());
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, ctx.resources.analytic_buffer());
      glBindVertexArray(ctx.empty_vao);
      glDrawArraysInstanced(GL_TRIANGLES, 0, 3, instances(ctx));
    }
    glDisable(GL_DEPTH_TEST);
    gl_check("surfaces pass");
  }

 private:
  ProgramPair raster_;
  ProgramPair analytic_;
};

// Beams: additive energy from the line-integral tables, one instanced draw of
// box proxies, back faces only (see beam.vert); a multi-view batch draws
// views x beams instances.
class BeamPass final : public Pass {
 public:
  BeamPass()
      : program_("beam", {"common.glsl", "beam.vert"},
                 {"common.glsl", "beam_math.glsl", "beam.frag"}) {}
  const char* name() const override { return "beams"; }
  void execute(FrameContext& ctx) override {
    const bool multi = ctx.views > 0;
    glBindFramebuffer(GL_FRAMEBUFFER, ctx.targets.beam_fbo.get());
    glUseProgram(program_.get(multi));
    glUniform3i(program_.uniform(multi, "u_table_size"), ctx.resources.table_d(),
                ctx.resources.table_s(), ctx.resources.table_f());
    glUniform1i(program_.uniform(multi, "u_has_surfaces"), ctx.scene.occluders.empty() ? 0 : 1);
    if (multi) glUniform1i(program_.uniform(multi, "u_view_beams"), ctx.resources.beam_count());
    const RenderSettings& rs = ctx.scene.render;
    const bool chord = rs.layout == TableLayout::kChord || rs.layout == TableLayout::kChordWarped;
    const bool warped = rs.layout == TableLayout::kWarped || rs.layout == TableLayout::kChordWarped;
    const std::pair<const char*, int> knobs[] = {
        {"u_warp_size", ctx.resources.warp_size()},
        {"u_method", static_cast<int>(rs.method)},
        {"u_chord", chord ? 1 : 0},
        {"u_warped", warped ? 1 : 0},
        {"u_shader_filter", rs.filter == TableFilter::kShader ? 1 : 0},
        {"u_samples", rs.samples},
        {"u_simpson", rs.rule == MarchRule::kSimpson ? 1 : 0},
        {"u_near_parallel", rs.near_parallel == NearParallel::kQuadrature ? 1 : 0}};
    for (const auto& [uniform, value] : knobs) {
      glUniform1i(program_.uniform(multi, uniform), value);
    }
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
    glDrawArraysInstanced(GL_TRIANGLES, 0, 36, ctx.resources.beam_count() * instances(ctx));
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDisable(GL_DEPTH_CLAMP);
    gl_check("beams pass");
  }

 private:
  ProgramPair program_;
};

// HDR -> display values in the output's bit depth.
class TonemapPass final : public Pass {
 public:
  TonemapPass()
      : program_("tonemap", {"common.glsl", "fullscreen.vert"}, {"common.glsl", "tonemap.frag"}) {}
  const char* name() const override { return "tonemap"; }
  void execute(FrameContext& ctx) override {
    const bool multi = ctx.views > 0;
    glBindFramebuffer(GL_FRAMEBUFFER, ctx.targets.output_fbo.get());
    glUseProgram(program_.get(multi));
    const OutputSettings& out = ctx.scene.output;
    glUniform1f(program_.uniform(multi, "u_exposure"), static_cast<float>(out.exposure));
    glUniform1i(program_.uniform(multi, "u_curve"), static_cast<int>(out.tone));
    glUniform1f(program_.uniform(multi, "u_levels"), out.bit_depth == 16 ? 65535.0f : 255.0f);
    glBindTextureUnit(0, ctx.targets.hdr.get());
    glBindVertexArray(ctx.empty_vao);
    glDrawArraysInstanced(GL_TRIANGLES, 0, 3, instances(ctx));
    gl_check("tonemap pass");
  }

 private:
  ProgramPair program_;
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
