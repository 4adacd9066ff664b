// The executors of the passes that every kind of frame shares: occluders
// (plain and G-buffer), direct light, photon splats and their resolve,
// beams, tone mapping and upscaling (rows in render/pass_catalog.cpp).
#include "render/core_passes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "gi/photon_map.hpp"
#include "render/gl_validate.hpp"
#include "shaders/shader_sources.hpp"

namespace beamcast {

namespace {

// Occluders: rasterized triangles (boxes, meshes) and ray-traced planes and
// spheres, depth-tested together; writes shaded colour and view depth.
class SurfacePass final : public Pass {
 public:
  explicit SurfacePass(bool gbuffer)
      : raster_("surface"), analytic_("analytic_occluder"), gbuffer_(gbuffer) {}
  void execute(FrameContext& ctx, const PassDecl& self) override {
    const bool multi = ctx.views > 0;
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);  // reversed Z
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glDisable(GL_DEPTH_CLAMP);  // triangles are clipped by the near and far planes
    const bool raster = ctx.resources.triangle_vertex_count() > 0;
    const bool analytic = ctx.resources.analytic_count() > 0;
    // The same draws serve "surfaces" (directional light) and "gbuffer" (lit scenes).
    const int gi = gbuffer_ ? 1 : 0;
    if (analytic) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, ctx.resources.analytic_buffer());
    // Per view: both draws into the view's framebuffer.
    const int views = multi ? ctx.views : 1;
    for (int v = 0; v < views; ++v) {
      glBindFramebuffer(GL_FRAMEBUFFER, ctx.targets.fbo(self, multi ? v : -1));
      if (raster) {
        glUseProgram(raster_.get(multi));
        if (multi) glUniform1i(raster_.uniform(true, "u_view"), v);
        glUniform1i(raster_.uniform(multi, "u_gi"), gi);
        glBindVertexArray(ctx.resources.triangle_vao());
        draw_arrays(GL_TRIANGLES, 0, ctx.resources.triangle_vertex_count());
      }
      if (analytic) {
        glUseProgram(analytic_.get(multi));
        if (multi) glUniform1i(analytic_.uniform(true, "u_view"), v);
        glUniform1i(analytic_.uniform(multi, "u_gi"), gi);
        glUniform1i(analytic_.uniform(multi, "u_count"), ctx.resources.analytic_count());
        glBindVertexArray(ctx.empty_vao);
        draw_arrays(GL_TRIANGLES, 0, 3);
      }
    }
    glDisable(GL_DEPTH_TEST);
    gl_check("surfaces pass");
  }

 private:
  ProgramPair raster_;
  ProgramPair analytic_;
  bool gbuffer_;  // the "gbuffer" row: G-buffer targets, lit-scene shading
};

// The projection of one face of a cube map: clip (s, t, m - 2 near, m) of a
// point relative to the cube's centre, where m is the coordinate along the
// face's axis and s, t the GL cube-map face coordinates (GL 4.5 table 8.19),
// so that the face's texel (s, t) / m holds what lies in that direction.
// Row-major.
std::array<float, 16> cube_face_matrix(int face, float near) {
  // (s, t, m) as rows of coefficients of (x, y, z).
  static constexpr float kRows[6][3][3] = {
      {{0, 0, -1}, {0, -1, 0}, {1, 0, 0}},   // +X
      {{0, 0, 1}, {0, -1, 0}, {-1, 0, 0}},   // -X
      {{1, 0, 0}, {0, 0, 1}, {0, 1, 0}},     // +Y
      {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}},   // -Y
      {{1, 0, 0}, {0, -1, 0}, {0, 0, 1}},    // +Z
      {{-1, 0, 0}, {0, -1, 0}, {0, 0, -1}},  // -Z
  };
  const auto& r = kRows[face];
  return {r[0][0], r[0][1], r[0][2], 0.0f,  //
          r[1][0], r[1][1], r[1][2], 0.0f,  //
          r[2][0], r[2][1], r[2][2], -2.0f * near, r[2][0], r[2][1], r[2][2], 0.0f};
}

// Direct light (shaders/direct_light.frag): one full-screen draw per view
// over the G-buffer, every light as its DirectPoints. Their cube shadow maps
// of the scene's triangles are rendered here on the first frame of a scene
// and kept while the geometry, lights and direct settings stay the same
// (SceneResources::shadow_key), so a camera-only change renders none.
class DirectPass final : public Pass {
 public:
  explicit DirectPass(bool split)
      : programs_("direct_light"), lean_("direct_light_lean"), shadow_("shadow_depth"),
        split_(split) {}
  void execute(FrameContext& ctx, const PassDecl& self) override {
    SceneResources& res = ctx.resources;
    const auto count = static_cast<GLsizei>(res.direct_points().size());
    if (count == 0) return;
    if (res.shadow_key() != key_) render_shadows(ctx);
    const bool multi = ctx.views > 0;
    // Without analytic occluders or a medium: the program without their code.
    const bool lean = res.analytic_count() == 0 && !ctx.scene.has_medium();
    ProgramPair& program = lean ? lean_ : programs_.get(ctx.scene);
    glUseProgram(program.get(multi));
    glUniform1i(program.uniform(multi, "u_point_count"), count);
    // With the split target (kDirectSplit) the interleaved points go there.
    const bool split = split_;
    glUniform1i(program.uniform(multi, "u_interleaved"), split ? res.direct_interleaved() : 0);
    glUniform1f(program.uniform(multi, "u_far"), far_);
    glUniform1f(program.uniform(multi, "u_texel"), 2.0f / static_cast<float>(size_));
    const GLint region_eye = set_medium_uniforms(program, multi, ctx);
    glUniform1i(program.uniform(multi, "u_count"), res.analytic_count());
    bind_gbuffer(ctx);
    glBindTextureUnit(3, cubes_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, res.direct_buffer());
    if (res.analytic_count() > 0)
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, res.analytic_buffer());
    begin_additive(ctx);
    if (split) glDisablei(GL_BLEND, 1);  // direct_split is written, not added to
    int view = 0;
    for_each_view_offset(ctx, self, program, "u_point_offset", res.direct_anchor(), [&] {
      set_region_eye(ctx, region_eye, view++);
      draw_arrays(GL_TRIANGLES, 0, 3);
    });
    glDisable(GL_BLEND);
    gl_check("direct pass");
  }

 private:
  void render_shadows(FrameContext& ctx) {
    const SceneResources& res = ctx.resources;
    const std::vector<DirectPoint>& points = res.direct_points();
    size_ = ctx.scene.gi.shadow_size;
    cubes_ = make_shadow_cube_array(size_, static_cast<GLsizei>(points.size()));
    // Distances are stored over the farthest the triangles can be from any
    // point (1 = nothing there: the clear value).
    const Aabb& box = res.mesh_bounds();
    double far = 0.0;
    for (const DirectPoint& p : points) {
      for (int c = 0; c < 8 && !box.empty(); ++c) {
        const Vec3 corner{(c & 1) ? box.hi[0] : box.lo[0], (c & 2) ? box.hi[1] : box.lo[1],
                          (c & 4) ? box.hi[2] : box.lo[2]};
        far = std::max(far, length(corner - p.position));
      }
    }
    // Without triangles every map stays clear: any finite distance is lit.
    far_ = box.empty() ? 1e30f : static_cast<float>(std::max(far * 1.01, 1e-30));
    const float near = 1e-5f * far_;
    GLint viewport[4];
    glGetIntegerv(GL_VIEWPORT, viewport);
    GLuint id = 0;
    glCreateFramebuffers(1, &id);
    GlFramebuffer fbo(id);
    glNamedFramebufferDrawBuffer(id, GL_NONE);
    glViewport(0, 0, size_, size_);
    glBindFramebuffer(GL_FRAMEBUFFER, id);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glUseProgram(shadow_.get(false));
    glUniform1f(shadow_.uniform(false, "u_far"), far_);
    const GLint offset = shadow_.uniform(false, "u_offset");
    const GLint face_matrix = shadow_.uniform(false, "u_face");
    glBindVertexArray(res.triangle_vao());
    const float one = 1.0f;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Vec3 off = res.mesh_anchor() - points[i].position;
      glUniform3f(offset, static_cast<float>(off[0]), static_cast<float>(off[1]),
                  static_cast<float>(off[2]));
      for (int face = 0; face < 6; ++face) {
        glNamedFramebufferTextureLayer(id, GL_DEPTH_ATTACHMENT, cubes_.get(), 0,
                                       static_cast<GLint>(6 * i) + face);
        glClearNamedFramebufferfv(id, GL_DEPTH, 0, &one);
        if (res.triangle_vertex_count() == 0) continue;
        const std::array<float, 16> m = cube_face_matrix(face, near);
        glUniformMatrix4fv(face_matrix, 1, GL_TRUE, m.data());
        draw_arrays(GL_TRIANGLES, 0, res.triangle_vertex_count());
      }
    }
    glDisable(GL_DEPTH_TEST);
    glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
    key_ = res.shadow_key();
    gl_check("direct pass: shadow maps");
  }

  RegionProgram programs_;
  ProgramPair lean_;
  ProgramPair shadow_;
  std::string key_;  // the SceneResources::shadow_key the maps are for
  GlTexture cubes_;  // depth cube-map array, 6 layers per direct point
  int size_ = 0;
  float far_ = 1.0f;
  bool split_;  // the interleaved row: interleaved lights into direct_split
};

// The photon splats' tests (shaders/photon_splat.frag, gi_resolve.frag; the
// CPU's SplatTests): a photon lights a surface point whose normal is within
// 25 degrees of its own (curved surfaces turn within a radius; a thin wall's
// other side is 180 degrees off) and that lies within a tenth of the radius
// of its plane (a parallel surface nearby: a slab's top over its floor).
constexpr float kSplatMinCos = 0.906f;
constexpr float kSplatMaxPlane = 0.1f;

// The pixels a seen light's projection can touch (its outline's
// parallelogram), 2 pixels wider on each side (a pixel meets the light only
// if its square meets the light's projection; the outline test's rays are
// within the pixel); every pixel if a corner has no place in the image (at
// or behind the near plane).
std::array<int, 4> light_pixel_rect(const LightOutline& q, const Camera& cam,
                                    const CameraBasis& b) {
  const Vec3 corners[4] = {q.corner, q.corner + q.u, q.corner + q.v, q.corner + q.u + q.v};
  return pixel_rect(corners, cam, b, 2);
}

// The splats' sum (gi_indirect) into hdr, upsampled, each splat pixel
// divided by the kernel-weighted share of its disk that lies on its own
// surface (its alpha, from the photon pass's share draw), or passed through
// with gi.edge_correction off (shaders/gi_resolve.frag).
class GiResolvePass final : public Pass {
  static constexpr std::size_t kMaxAaLights = 8;  // shaders/gi_resolve.frag

 public:
  GiResolvePass() : program_("gi_resolve") {}
  void execute(FrameContext& ctx, const PassDecl& self) override {
    const bool multi = ctx.views > 0;
    ProgramPair& program = program_;
    glUseProgram(program.get(multi));
    glUniform1f(program.uniform(multi, "u_radius"),
                static_cast<float>(ctx.resources.photon_radius()));
    glUniform1f(program.uniform(multi, "u_min_cos"), kSplatMinCos);
    glUniform1f(program.uniform(multi, "u_max_plane"), kSplatMaxPlane);
    set_photon_lod(program, multi, ctx.scene.gi);
    glUniform1i(program.uniform(multi, "u_correct"), ctx.scene.gi.edge_correction ? 1 : 0);
    glUniform1i(program.uniform(multi, "u_splat_scale"), ctx.targets.splat_scale());
    const SplatBands& bands = ctx.targets.splat_bands();
    glUniform2i(program.uniform(multi, "u_band_layout"), bands.band_h, bands.stride);
    bind_gbuffer(ctx);
    glBindTextureUnit(3, ctx.targets.texture(TargetId::kGiIndirect));
    // The interleaved direct light's quarters, filtered here (direct_filter.glsl).
    const bool split = ctx.plan.written(TargetId::kDirectSplit) && ctx.resources.direct_interleaved() > 0;
    glUniform1i(program.uniform(multi, "u_direct_split"), split ? 1 : 0);
    if (split) {
      glBindTextureUnit(4, ctx.targets.texture(TargetId::kDirectSplit));
    } else {
      bind_view_placeholder(ctx, 4);  // compiled in, not read
    }
    begin_additive(ctx);
    // Seen lights whose outlines are antialiased: corners relative to the
    // first one's (in double, then float).
    std::vector<std::pair<LightOutline, Color>> seen;
    if (ctx.scene.gi.light_antialias) {
      for (const Light& l : ctx.scene.lights) {
        std::visit(
            [&](const auto& kind) {
              const std::optional<LightOutline> o = kind.outline();
              if (o && seen.size() < kMaxAaLights) {
                seen.emplace_back(*o, kind.radiance_scale() * l.flux);
              }
            },
            l.shape);
      }
    }
    const Vec3 anchor = seen.empty() ? Vec3{} : seen[0].first.corner;
    glUniform1i(program.uniform(multi, "u_aa_lights"), static_cast<GLint>(seen.size()));
    for (std::size_t k = 0; k < seen.size(); ++k) {
      const auto& [q, radiance] = seen[k];
      const std::string i = "[" + std::to_string(k) + "]";
      auto set = [&](const char* name, const Vec3& v) {
        glUniform3f(program.uniform(multi, (name + i).c_str()), static_cast<float>(v[0]),
                    static_cast<float>(v[1]), static_cast<float>(v[2]));
      };
      glUniform1i(program.uniform(multi, ("u_light_code" + i).c_str()), q.code);
      set("u_light_corner", q.corner - anchor);
      set("u_light_u", q.u);
      set("u_light_v", q.v);
      set("u_light_radiance", Vec3{radiance[0], radiance[1], radiance[2]});
      // The pixels whose outline test can find the light (one camera; a
      // multi-view batch tests every pixel).
      const std::array<int, 4> rect =
          multi ? kEveryPixel
                : light_pixel_rect(q, ctx.camera, ctx.basis);
      glUniform4i(program.uniform(multi, ("u_light_rect" + i).c_str()), rect[0], rect[1], rect[2],
                  rect[3]);
    }
    for_each_view_offset(ctx, self, program, "u_light_offset", anchor,
                         [] { draw_arrays(GL_TRIANGLES, 0, 3); });
    glDisable(GL_BLEND);
    gl_check("gi_resolve pass");
  }

 private:
  ProgramPair program_;
};

// Photon splatting: one draw of camera-facing quads (QuadIndices), one per
// photon; the fragment shader reads the G-buffer and adds the photon's
// reflected radiance (shaders/photon_splat.frag), additively into hdr.
class PhotonPass final : public Pass {
 public:
  void execute(FrameContext& ctx, const PassDecl& self) override {
    if (ctx.resources.photon_count() == 0) return;
    const bool multi = ctx.views > 0;
    ProgramPair& program =
        programs_.get(std::string("photon_splat") + kernel_suffix(ctx.scene.gi.kernel));
    glUseProgram(program.get(multi));
    const float radius = static_cast<float>(ctx.resources.photon_radius());
    glUniform1f(program.uniform(multi, "u_radius"), radius);
    glUniform1f(program.uniform(multi, "u_min_cos"), kSplatMinCos);
    glUniform1f(program.uniform(multi, "u_max_plane"), kSplatMaxPlane);
    set_photon_lod(program, multi, ctx.scene.gi);
    bind_gbuffer(ctx);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, ctx.resources.photon_buffer());
    begin_additive(ctx);
    // Splatted at the kSplat size, band by band (SplatBands): the viewport
    // shrinks and shifts for this pass, the scissor keeps each band's draw
    // to its own rows.
    const int scale = ctx.targets.splat_scale();
    const SplatBands& bands = ctx.targets.splat_bands();
    glUniform1i(program.uniform(multi, "u_splat_scale"), scale);
    GLint viewport[4];
    glGetIntegerv(GL_VIEWPORT, viewport);
    const bool banded = bands.bands > 1;
    if (banded) glEnable(GL_SCISSOR_TEST);
    // Runs `draw` once per band with `prog`'s u_band_shift (a band's texel
    // plus it is its grid texel) set, and the disks' cull uniforms
    // (u_band_ndc: the band's rows in NDC y, a pixel wider each side; the
    // share draw has none).
    auto per_band = [&](ProgramPair& prog, auto&& draw) {
      const GLint shift = prog.uniform(multi, "u_band_shift");
      const GLint ndc = prog.uniform(multi, "u_band_ndc");
      glUniform1i(prog.uniform(multi, "u_band_cull"), banded ? 1 : 0);
      const float row = 2.0f / static_cast<float>(bands.h);
      for (int b = 0; b < bands.bands; ++b) {
        glViewport(b * bands.stride, -b * bands.band_h, bands.w, bands.h);
        if (banded) glScissor(b * bands.stride, 0, bands.w, bands.band_h);
        glUniform2i(shift, -b * bands.stride, b * bands.band_h);
        glUniform2f(ndc, static_cast<float>(b * bands.band_h - 1) * row - 1.0f,
                    static_cast<float>((b + 1) * bands.band_h + 1) * row - 1.0f);
        draw();
      }
    };
    // gi.edge_correction: each splat pixel's share of its disk on its own
    // surface into the target's alpha (shaders/gi_share.frag), for gi_resolve.
    if (ctx.scene.gi.edge_correction) {
      ProgramPair& share =
          programs_.get(std::string("gi_share") + kernel_suffix(ctx.scene.gi.kernel));
      glUseProgram(share.get(multi));
      glUniform1f(share.uniform(multi, "u_radius"), radius);
      glUniform1f(share.uniform(multi, "u_min_cos"), kSplatMinCos);
      glUniform1f(share.uniform(multi, "u_max_plane"), kSplatMaxPlane);
      glUniform1i(share.uniform(multi, "u_splat_scale"), scale);
      for_each_view(ctx, self, share,
                    [&] { per_band(share, [] { draw_arrays(GL_TRIANGLES, 0, 3); }); });
      glUseProgram(program.get(multi));
    }
    // Two draws: the global map's photons, then the caustic map's with their
    // own (smaller) radius.
    const GLint radius_uniform = program.uniform(multi, "u_radius");
    // The buffer holds the drawn share of each map (gi.display_fraction),
    // its power already scaled, clustered (gi.cluster): all of it is drawn.
    const GLsizei split = ctx.resources.photon_caustic_first();
    const GLsizei caustic = ctx.resources.photon_count() - split;
    glUniform1f(program.uniform(multi, "u_power_scale"), 1.0f);
    const float caustic_radius = static_cast<float>(ctx.resources.caustic_radius());
    for_each_view_offset(ctx, self, program, "u_photon_offset", ctx.resources.photon_anchor(), [&] {
      per_band(program, [&] {
        if (split > 0) {
          glUniform1f(radius_uniform, radius);
          quads_.draw(0, split);
        }
        if (caustic > 0) {
          glUniform1f(radius_uniform, caustic_radius);
          quads_.draw(split, caustic);
        }
      });
    });
    if (banded) glDisable(GL_SCISSOR_TEST);
    glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
    glDisable(GL_BLEND);
    gl_check("photons pass");
  }

 private:
  LazyPrograms programs_;  // by kernel
  QuadIndices quads_;
};

// Beams: additive energy from the line-integral tables, one instanced draw of
// box proxies, back faces only (see beam.vert); one such draw per view in a
// multi-view batch.
class BeamPass final : public Pass {
 public:
  BeamPass() : plain_("beam"), fogged_("beam_medium") {}
  ProgramPair& volumes_program(const Scene& scene, bool medium) {
    if (!medium) {
      if (!plain_volumes_) plain_volumes_.emplace("beam_volumes");
      return *plain_volumes_;
    }
    if (!fogged_volumes_) fogged_volumes_.emplace("beam_medium_volumes");
    return fogged_volumes_->get(scene);
  }
  void execute(FrameContext& ctx, const PassDecl& self) override {
    const bool multi = ctx.views > 0;
    // Scenes with a medium use the program with it compiled in (built on
    // first use); the others the program without, unchanged by media.
    const bool fog = ctx.scene.has_medium();
    const Medium settings = ctx.scene.medium.value_or(Medium{});
    const Medium* medium = fog ? &settings : nullptr;
    // Scenes with volumes: the programs with their transmittance knots
    // compiled in (shaders/volumes_on.glsl), built on first use.
    const bool volumes = ctx.plan.written(TargetId::kVolumeT0);
    ProgramPair& program = volumes  ? volumes_program(ctx.scene, medium != nullptr)
                           : medium ? fogged_.get(ctx.scene)
                                    : plain_;
    glUseProgram(program.get(multi));
    glUniform3i(program.uniform(multi, "u_table_size"), ctx.resources.table_d(),
                ctx.resources.table_s(), ctx.resources.table_f());
    // A ray ends at the nearest surface if any planned pass wrote view depth.
    const bool surfaces = ctx.plan.written(TargetId::kViewDepth);
    glUniform1i(program.uniform(multi, "u_has_surfaces"), surfaces ? 1 : 0);
    if (multi) glUniform1i(program.uniform(multi, "u_view_beams"), ctx.resources.beam_count());
    const RenderSettings& rs = ctx.scene.render;
    GLint region_eye = -1;
    if (medium) {
      region_eye = set_medium_uniforms(program, multi, ctx);
      glUniform1f(program.uniform(multi, "u_medium_step"), static_cast<float>(medium->beam_step));
      glUniform1i(program.uniform(multi, "u_medium_rule"),
                  medium->beam_rule == BeamMediumRule::kMidpoint ? 1 : 0);
    }
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
      glUniform1i(program.uniform(multi, uniform), value);
    }
    glBindTextureUnit(0, ctx.resources.g_texture());
    glBindTextureUnit(1, ctx.resources.f_texture());
    bind_view_target_or_placeholder(ctx, 2, TargetId::kViewDepth);
    glBindTextureUnit(3, ctx.resources.warp_texture());
    if (medium) glBindTextureUnit(4, ctx.resources.moment_texture());
    if (volumes) {
      glBindTextureUnit(5, ctx.targets.texture(TargetId::kVolumeT0));
      glBindTextureUnit(6, ctx.targets.texture(TargetId::kVolumeT1));
    }
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
    int view = 0;
    for_each_view(ctx, self, program, [&] {
      const int v = view++;
      if (medium) set_region_eye(ctx, region_eye, v);
      if (volumes) set_volume_box(program, multi, ctx, v);
      draw_arrays_instanced(GL_TRIANGLES, 0, 36, ctx.resources.beam_count());
    });
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDisable(GL_DEPTH_CLAMP);
    gl_check("beams pass");
  }

 private:
  ProgramPair plain_;
  RegionProgram fogged_;
  std::optional<ProgramPair> plain_volumes_;
  std::optional<RegionProgram> fogged_volumes_;
};

// HDR -> display values in the output's bit depth.
class TonemapPass final : public Pass {
 public:
  TonemapPass() : program_("tonemap") {}
  void execute(FrameContext& ctx, const PassDecl& self) override {
    const bool multi = ctx.views > 0;
    glUseProgram(program_.get(multi));
    const OutputSettings& out = ctx.scene.output;
    glUniform1f(program_.uniform(multi, "u_exposure"), static_cast<float>(out.exposure));
    glUniform1i(program_.uniform(multi, "u_curve"), static_cast<int>(out.tone));
    glUniform1f(program_.uniform(multi, "u_levels"), out.bit_depth == 16 ? 65535.0f : 255.0f);
    glBindTextureUnit(0, ctx.targets.texture(TargetId::kHdr));
    glBindVertexArray(ctx.empty_vao);
    for_each_view(ctx, self, program_, [] { draw_arrays(GL_TRIANGLES, 0, 3); });
    gl_check("tonemap pass");
  }

 private:
  ProgramPair program_;
};

// The tone-mapped output (render size) to the camera's size, bilinear; only
// planned for scaled frames. Reads the output through tonemap's framebuffer.
class UpscalePass final : public Pass {
 public:
  void execute(FrameContext& ctx, const PassDecl& self) override {
    const PassDecl* source = nullptr;
    for (const PassDecl* p : ctx.plan.passes) {
      if (p != &self && !p->writes.empty() && p->writes.front() == self.reads.front()) source = p;
    }
    if (!source) throw GlError("upscale: no planned pass writes its source");
    const int views = ctx.views > 0 ? ctx.views : 1;
    for (int v = 0; v < views; ++v) {
      const int view = ctx.views > 0 ? v : -1;
      glBlitNamedFramebuffer(ctx.targets.fbo(*source, view), ctx.targets.fbo(self, view), 0, 0,
                             ctx.camera.width, ctx.camera.height, 0, 0, ctx.output_width,
                             ctx.output_height, GL_COLOR_BUFFER_BIT, GL_LINEAR);
    }
    gl_check("upscale pass");
  }
};

}  // namespace

std::unique_ptr<Pass> make_surface_pass(bool gbuffer) { return std::make_unique<SurfacePass>(gbuffer); }
std::unique_ptr<Pass> make_direct_pass(bool split) { return std::make_unique<DirectPass>(split); }
std::unique_ptr<Pass> make_photon_pass() { return std::make_unique<PhotonPass>(); }
std::unique_ptr<Pass> make_gi_resolve_pass() { return std::make_unique<GiResolvePass>(); }
std::unique_ptr<Pass> make_beam_pass() { return std::make_unique<BeamPass>(); }
std::unique_ptr<Pass> make_tonemap_pass() { return std::make_unique<TonemapPass>(); }
std::unique_ptr<Pass> make_upscale_pass() { return std::make_unique<UpscalePass>(); }

}  // namespace beamcast
