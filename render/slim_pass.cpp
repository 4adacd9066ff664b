#include "render/slim_pass.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <variant>

#include "protocol/occluders/slim.hpp"
#include "render/passes.hpp"
#include "render/gl_validate.hpp"

namespace beamcast {

namespace {

// One sphere as slim_points.vert reads it (std430: nine vec4).
struct SlimGpu {
  float center[4];
  float axis_u[4];
  float axis_v[4];
  float axis_w[4];
  float p1[4];
  float p2[4];
  float q1[4];
  float q2[4];
  float albedo[4];
};
static_assert(sizeof(SlimGpu) == 144);

struct DrawCommand {  // DrawArraysIndirectCommand
  std::uint32_t count, instance_count, first, base_instance;
};

// True if every point of the sphere's patch faces away from the eye: its
// normals lie within atan(max slope) of the local w axis, the directions
// from the eye to its points within the sphere's angular radius of the
// direction to its centre (perspective) or along forward (orthographic).
bool faces_away(const SlimSphere& sphere, const Vec3& to_centre, double distance, bool ortho,
                const Vec3& forward) {
  if (!ortho && distance <= sphere.radius) return false;  // the eye is inside it
  const Vec3 w = sphere.to_world({0.0, 0.0, 1.0}) - sphere.center;
  const Vec3 view = ortho ? forward : (1.0 / distance) * to_centre;
  const double alpha = std::atan(slim_max_slope(sphere));
  const double beta = ortho ? 0.0 : std::asin(sphere.radius / distance);
  const double margin = 0.5 * std::numbers::pi - alpha - beta - 1e-3;
  return margin > 0.0 && dot(w, view) > std::cos(margin);
}

}  // namespace

double slim_cell_diagonal(const SlimSettings& settings) {
  return settings.evaluation == SlimEvaluation::kField ? 6.0 : std::sqrt(3.0) / 2.0;
}

SlimGrid slim_grid(const SlimSphere& sphere, const Camera& cam, const CameraBasis& basis,
                   const SlimSettings& settings) {
  const Vec3 p = sphere.center - basis.eye;
  const double r = sphere.radius;
  const double x = dot(p, basis.right), y = dot(p, basis.up), z = dot(p, basis.forward);
  if (z + r < cam.near_plane || z - r > cam.far_plane) return {};
  const bool ortho = cam.projection == Projection::kOrthographic;
  if (settings.cull_backfaces && faces_away(sphere, p, length(p), ortho, basis.forward)) return {};
  const double th = ortho ? basis.half_height : basis.tan_half_fov;
  const double tw = th * basis.aspect;
  // Culled outside the frustum (a side plane farther than r away).
  if (ortho ? std::abs(x) > tw + r || std::abs(y) > th + r
            : (std::abs(x) - tw * z) / std::sqrt(1.0 + tw * tw) > r ||
                  (std::abs(y) - th * z) / std::sqrt(1.0 + th * th) > r) {
    return {};
  }
  // Pixels per world unit at the depth d (orthographic: everywhere).
  auto ppw = [&](double d) { return cam.height / (2.0 * th * (ortho ? 1.0 : d)); };
  const double ppw_centre = ppw(std::max(z, cam.near_plane));
  // N: the sphere's projected width, at its centre's depth (the seed's);
  // nearer parts project wider, which the second stage fills.
  const double n_px = 2.0 * r * ppw_centre;
  SlimGrid g;
  g.m = static_cast<std::uint32_t>(
      std::clamp(std::ceil(2.0 * n_px / settings.sampling), 1.0, static_cast<double>(kSlimMaxGrid)));
  if (settings.fill_holes) {
    // The most any cell needs: its longer projected diagonal (the shader's
    // rule, slim_points.vert) at 7 x 7 cells spread over the sphere (those inside it), exact
    // finite differences in double, with a 10% margin over the shader's 5%
    // for the cells between them (the projection of a quadratic patch
    // changes slowly across it). Without it every cell would get the
    // worst case of the whole sphere.
    const double h = 2.0 * r / g.m;
    auto pixel = [&](double u, double v, std::array<double, 2>* out) {
      const Vec3 q = sphere.surface_point(u, v) - basis.eye;
      const double qz = dot(q, basis.forward);
      if (!ortho && !(qz > cam.near_plane)) return false;
      const double scale = ppw(qz);
      (*out)[0] = dot(q, basis.right) * scale;
      (*out)[1] = dot(q, basis.up) * scale;
      return true;
    };
    double worst = 0.0;
    constexpr int kProbes = 7;
    for (int i = 0; i < kProbes; ++i) {
      for (int j = 0; j < kProbes; ++j) {
        const double u = -r + (2.0 * r - h) * i / (kProbes - 1);
        const double v = -r + (2.0 * r - h) * j / (kProbes - 1);
        // Only cells that hold points (inside the sphere).
        if (std::hypot(u + 0.5 * h, v + 0.5 * h, sphere.height(u + 0.5 * h, v + 0.5 * h)) >= r) continue;
        std::array<double, 2> p00{}, p10{}, p01{}, p11{};
        if (!pixel(u, v, &p00) || !pixel(u + h, v, &p10) || !pixel(u, v + h, &p01) ||
            !pixel(u + h, v + h, &p11)) {
          worst = std::numeric_limits<double>::infinity();  // crosses the near plane
          continue;
        }
        worst = std::max({worst, std::hypot(p11[0] - p00[0], p11[1] - p00[1]),
                          std::hypot(p10[0] - p01[0], p10[1] - p01[1])});
      }
    }
    g.s =
        static_cast<std::uint32_t>(std::clamp(std::ceil(1.1 * worst / slim_cell_diagonal(settings)),
                                              1.0, static_cast<double>(kSlimMaxFill)));
  }
  return g;
}

std::string SlimResources::content_key(const Scene& scene) {
  std::string key = "slim|";
  key.push_back(scene.slim.evaluation == SlimEvaluation::kPatch ? 'p' : 's');
  for (const Occluder& occ : scene.occluders) {
    if (const auto* slim = std::get_if<SlimOccluder>(&occ.shape)) {
      key += "|" + slim->surface->content_key();
      key.append(reinterpret_cast<const char*>(occ.albedo.data()), sizeof(occ.albedo));
      key.push_back(static_cast<char>('0' + static_cast<int>(occ.material.type)));
    }
  }
  return key;
}

SlimResources::SlimResources(const Scene& scene, SceneGpuCache* content) {
  // The records depend only on the scene's content: kept across renders.
  const std::string key = content ? content_key(scene) : std::string();
  if (content) st_ = content->find<SlimStatic>(key);
  if (st_) return;
  st_ = make_static(scene);
  if (content) content->put(key, st_, st_->bytes + key.size());
}

std::shared_ptr<const SlimStatic> SlimResources::make_static(const Scene& scene) {
  auto st = std::make_shared<SlimStatic>();
  std::vector<const SlimSphere*>& spheres = st->spheres;
  Aabb box;
  std::vector<const Occluder*> occluder_of;  // each sphere's occluder (its albedo)
  // Each sphere's height range, which only the patch evaluation reads
  // (computed on first use by the shared surface).
  const bool patch = scene.slim.evaluation == SlimEvaluation::kPatch;
  std::vector<const std::array<double, 2>*> range_of;
  // Spheres without a crease first, then those with one (crease_begin()).
  for (const bool creases : {false, true}) {
    if (creases) st->crease_begin = spheres.size();
    for (const Occluder& occ : scene.occluders) {
      if (const auto* slim = std::get_if<SlimOccluder>(&occ.shape)) {
        if (!creases) st->surfaces.push_back(slim->surface);
        const auto* ranges = patch ? slim->surface->height_ranges().data() : nullptr;
        for (std::size_t k = 0; k < slim->spheres().size(); ++k) {
          if ((slim->spheres()[k].crease != SlimCrease::kNone) != creases) continue;
          spheres.push_back(&slim->spheres()[k]);
          occluder_of.push_back(&occ);
          range_of.push_back(ranges ? ranges + k : nullptr);
        }
        if (!creases) box.grow(slim->bounds());
      }
    }
  }
  st->box = box;
  if (!box.empty()) st->anchor = 0.5 * (box.lo + box.hi);
  const Vec3& anchor = st->anchor;
  std::vector<SlimGpu> data(spheres.size());
  std::vector<std::uint32_t> index(spheres.size());
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const SlimSphere& s = *spheres[i];
    const Occluder& occ = *occluder_of[i];
    SlimGpu& d = data[i];
    auto put = [](float* out, const Vec3& v, double w) {
      for (int k = 0; k < 3; ++k) out[k] = static_cast<float>(v[k]);
      out[3] = static_cast<float>(w);
    };
    put(d.center, s.center - anchor, s.radius);
    put(d.axis_u, s.to_world({1.0, 0.0, 0.0}) - s.center, 0.0);
    put(d.axis_v, s.to_world({0.0, 1.0, 0.0}) - s.center, 0.0);
    put(d.axis_w, s.to_world({0.0, 0.0, 1.0}) - s.center, 0.0);
    for (int k = 0; k < 4; ++k) {
      d.p1[k] = static_cast<float>(s.poly.c[k]);
      d.q1[k] = static_cast<float>(s.poly2.c[k]);
    }
    d.p2[0] = static_cast<float>(s.poly.c[4]);
    d.p2[1] = static_cast<float>(s.poly.c[5]);
    d.p2[2] = static_cast<float>(s.crease);
    // The patch's normal cone (slim_patch_plan.comp's backface cull).
    d.p2[3] = static_cast<float>(std::atan(slim_max_slope(s)));
    d.q2[0] = static_cast<float>(s.poly2.c[4]);
    d.q2[1] = static_cast<float>(s.poly2.c[5]);
    // The slab holding the patch's heights inside the sphere (slim_patch_plan.comp).
    if (range_of[i]) {
      d.q2[2] = static_cast<float>((*range_of[i])[0]);
      d.q2[3] = static_cast<float>((*range_of[i])[1]);
    }
    put(d.albedo, occ.albedo, static_cast<double>(occ.material.type));
    index[i] = static_cast<std::uint32_t>(i);
  }
  if (spheres.empty()) return st;
  st->sphere_ssbo = make_buffer(data);
  st->index_vbo = make_buffer(index);
  st->bytes = data.size() * sizeof(SlimGpu) + index.size() * sizeof(std::uint32_t) +
              spheres.size() * sizeof(const SlimSphere*);
  GLuint id = 0;
  glCreateVertexArrays(1, &id);
  st->vao = GlVertexArray(id);
  glVertexArrayVertexBuffer(id, 0, st->index_vbo.get(), 0, sizeof(std::uint32_t));
  glEnableVertexArrayAttrib(id, 0);
  glVertexArrayAttribIFormat(id, 0, 1, GL_UNSIGNED_INT, 0);
  glVertexArrayAttribBinding(id, 0, 0);
  glVertexArrayBindingDivisor(id, 0, 1);  // one sphere per instance: the command's base instance
  gl_check("SlimResources");
  return st;
}

void SlimResources::plan_patches(std::size_t views) {
  slots_.assign(views, static_cast<std::int64_t>(st_->spheres.size()));
  if (!corner_ssbo_ && !st_->spheres.empty()) {
    corner_ssbo_ = make_buffer(st_->spheres.size() * 4 * 4 * sizeof(float), nullptr);
  }
}

void SlimResources::plan_views(const std::vector<Camera>& cams, const std::vector<CameraBasis>& bases,
                               const SlimSettings& settings) {
  const std::size_t n = st_->spheres.size();
  const std::size_t views = cams.size();
  std::vector<DrawCommand> commands(n * views);
  std::vector<std::uint32_t> grids(2 * n * views);
  slots_.assign(views, 0);
  for (std::size_t v = 0; v < views; ++v) {
    for (std::size_t i = 0; i < n; ++i) {
      const SlimGrid g = slim_grid(*st_->spheres[i], cams[v], bases[v], settings);
      const std::uint64_t count = std::uint64_t{g.m} * g.m * g.s * g.s;
      commands[v * n + i] = {static_cast<std::uint32_t>(count), g.m > 0 ? 1u : 0u, 0,
                             static_cast<std::uint32_t>(i)};
      grids[2 * (v * n + i)] = g.m;
      grids[2 * (v * n + i) + 1] = g.s;
      slots_[v] += g.m > 0 ? static_cast<std::int64_t>(count) : 0;
    }
  }
  if (n == 0) return;
  if (views > capacity_views_) {
    GLuint id = 0;
    glCreateBuffers(1, &id);
    command_buffer_ = GlBuffer(id);
    glNamedBufferStorage(id, static_cast<GLsizeiptr>(commands.size() * sizeof(DrawCommand)), nullptr,
                         GL_DYNAMIC_STORAGE_BIT);
    glCreateBuffers(1, &id);
    grid_ssbo_ = GlBuffer(id);
    glNamedBufferStorage(id, static_cast<GLsizeiptr>(grids.size() * sizeof(std::uint32_t)), nullptr,
                         GL_DYNAMIC_STORAGE_BIT);
    capacity_views_ = views;
  }
  glNamedBufferSubData(command_buffer_.get(), 0,
                       static_cast<GLsizeiptr>(commands.size() * sizeof(DrawCommand)), commands.data());
  glNamedBufferSubData(grid_ssbo_.get(), 0, static_cast<GLsizeiptr>(grids.size() * sizeof(std::uint32_t)),
                       grids.data());
  gl_check("SlimResources::plan_views");
}

namespace {

// Full-screen draws of the slim passes (the accumulate pass's depth copy,
// the resolve) touch only the pixels the SLIM surfaces' bounds can reach
// in view `view` (-1: the single camera): a scissor box, one pixel wider.
void scissor_to_slim(const FrameContext& ctx, const SlimResources& slim, int view) {
  const Camera& cam = view < 0 ? ctx.camera : (*ctx.view_cameras)[static_cast<std::size_t>(view)];
  const CameraBasis& b = view < 0 ? ctx.basis : (*ctx.view_bases)[static_cast<std::size_t>(view)];
  const Aabb& box = slim.bounds();
  std::array<Vec3, 8> corners;
  for (int k = 0; k < 8; ++k) {
    corners[static_cast<std::size_t>(k)] = {(k & 1) ? box.hi[0] : box.lo[0],
                                            (k & 2) ? box.hi[1] : box.lo[1],
                                            (k & 4) ? box.hi[2] : box.lo[2]};
  }
  const std::array<int, 4> r = pixel_rect(corners, cam, b, 1);
  const int x0 = std::clamp(r[0], 0, cam.width), y0 = std::clamp(r[1], 0, cam.height);
  const int x1 = std::clamp(r[2] + 1, 0, cam.width), y1 = std::clamp(r[3] + 1, 0, cam.height);
  glEnable(GL_SCISSOR_TEST);
  glScissor(x0, y0, std::max(0, x1 - x0), std::max(0, y1 - y0));
}

// Field evaluation: the second point of the centre ray lies this many pixel
// footprints behind the first (the nearest depth).
constexpr float kSlimFieldStep = 2.0f;

// Passes 1 and 2: every sphere's points, one indirect command each, per
// view; or with slim.evaluation "patch" one rectangle per sphere.
class SlimPointsPass final : public Pass {
 public:
  explicit SlimPointsPass(bool depth) : depth_(depth) {}
  void execute(FrameContext& ctx, const PassDecl& self) override {
    SlimResources* slim = ctx.resources.slim();
    if (!slim || slim->sphere_count() == 0) return;
    const bool multi = ctx.views > 0;
    const bool patch = ctx.scene.slim.evaluation == SlimEvaluation::kPatch;
    const std::string name = depth_ ? "slim_depth" : "slim_accumulate";
    ProgramPair& program = programs_.get(patch ? name + "_patch" : name);
    // Patch evaluation: the crease spheres (after crease_begin()) with the
    // crease rule compiled in, the others without it.
    const auto n = static_cast<GLsizei>(slim->sphere_count());
    const auto plain = static_cast<GLsizei>(slim->crease_begin());
    ProgramPair* creases = patch && plain < n ? &programs_.get(name + "_patch_creases") : nullptr;
    if (depth_ && patch) slim->plan_patches(multi ? ctx.views : 1);
    if (depth_ && !patch) {  // the first of the slim passes plans the frame's samples
      if (multi) {
        slim->plan_views(*ctx.view_cameras, *ctx.view_bases, ctx.scene.slim);
      } else {
        slim->plan_views({ctx.camera}, {ctx.basis}, ctx.scene.slim);
      }
    }
    glBindTextureUnit(0, ctx.targets.texture(TargetId::kViewDepth));
    if (!depth_) {
      glBindTextureUnit(1, ctx.targets.texture(TargetId::kSlimNear));
      glBindTextureUnit(2, ctx.targets.texture(TargetId::kSlimRadius));
    }
    for (ProgramPair* p : {&program, creases}) {
      if (!p) continue;
      glUseProgram(p->get(multi));
      if (!depth_) {
        glUniform1f(p->uniform(multi, "u_threshold"),
                    static_cast<float>(ctx.scene.slim.depth_threshold));
        glUniform1f(p->uniform(multi, "u_step"), kSlimFieldStep);
      }
    }
    glUseProgram(program.get(multi));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, slim->sphere_buffer());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, slim->grid_buffer());
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, slim->command_buffer());
    glBindVertexArray(slim->instance_vao());
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    // Field evaluation: points cover the pixels their sample can stand for
    // (slim_points.vert sets the size); the seed's blend: single pixels.
    const bool field = ctx.scene.slim.evaluation != SlimEvaluation::kBlend;
    glUniform1i(program.uniform(multi, "u_field"), field ? 1 : 0);
    glUniform1f(program.uniform(multi, "u_cell_diag"),
                static_cast<float>(slim_cell_diagonal(ctx.scene.slim)));
    glUniform1i(program.uniform(multi, "u_cull_backfaces"), ctx.scene.slim.cull_backfaces ? 1 : 0);
    if (field) {
      glEnable(GL_PROGRAM_POINT_SIZE);
    } else {
      glDisable(GL_PROGRAM_POINT_SIZE);
      glPointSize(1.0f);
    }
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glBlendEquation(depth_ ? GL_MIN : GL_FUNC_ADD);
    const GLint grid_base = program.uniform(multi, "u_grid_base");
    int view = 0;
    if (patch) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 8, slim->corner_buffer());
    const bool depth_cull = patch && !depth_;
    for_each_view_offset(ctx, self, program, "u_offset", slim->anchor(), [&] {
      // The view's targets are cleared here, over the surfaces' pixel
      // bounds only (the plan does not clear them: nothing reads them
      // outside those bounds), and the draws stay inside the bounds too.
      scissor_to_slim(ctx, *slim, multi ? view : -1);
      if (depth_) {
        const float none[4] = {FrameTargets::kNoSurface, 0.0f, 0.0f, 0.0f};
        for (GLint b = 0; b < 2; ++b) glClearBufferfv(GL_COLOR, b, none);
      } else {
        const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
        for (GLint b = 0; b < 5; ++b) glClearBufferfv(GL_COLOR, b, zero);
      }
      if (patch) {  // one rectangle per sphere (slim_patch.vert)
        plan_patch_corners(ctx, *slim, multi ? view : -1);
        glUseProgram(program.get(multi));
        if (depth_cull) {
          // slim_near into the depth buffer (slim_near_depth.frag), then
          // the rectangles depth-tested against it (slim_patch.vert).
          ProgramPair& copy = programs_.get("slim_near_depth");
          glUseProgram(copy.get(multi));
          if (multi) glUniform1i(copy.uniform(true, "u_view"), view);
          glDisable(GL_BLEND);
          glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
          glEnable(GL_DEPTH_TEST);
          glDepthFunc(GL_ALWAYS);
          glDepthMask(GL_TRUE);
          draw_arrays(GL_TRIANGLES, 0, 3);
          glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
          glDepthFunc(GL_GEQUAL);
          glDepthMask(GL_FALSE);
          glEnable(GL_BLEND);
          glUseProgram(program.get(multi));
        }
        if (plain > 0) quads_.draw(0, plain);
        if (creases) {
          // The crease spheres' run with its program (this view's offset
          // and index set on it as for_each_view_offset set them on the
          // plain one).
          glUseProgram(creases->get(multi));
          set_view_offset(ctx, creases->uniform(multi, "u_offset"), multi ? view : -1,
                          slim->anchor());
          if (multi) glUniform1i(creases->uniform(true, "u_view"), view);
          quads_.draw(plain, n - plain);
          glUseProgram(program.get(multi));  // the next view's uniforms go to the plain one
        }
        if (depth_cull) {
          glDepthMask(GL_TRUE);
          glDisable(GL_DEPTH_TEST);
        }
        ++view;
        return;
      }
      glUniform1i(grid_base, view * n);
      const auto offset = static_cast<std::intptr_t>(view) * n * 16;
      multi_draw_arrays_indirect(GL_POINTS, reinterpret_cast<const void*>(offset), n, 0);
      ++view;
    });
    glDisable(GL_SCISSOR_TEST);
    glBlendEquation(GL_FUNC_ADD);
    glDisable(GL_BLEND);
    glDisable(GL_PROGRAM_POINT_SIZE);
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
    gl_check(depth_ ? "slim_depth pass" : "slim_accumulate pass");
  }

 private:
  // slim.evaluation "patch": the rectangles of view `view` (-1: the single
  // camera) into the corner buffer (slim_patch_plan.comp), before each
  // pass's draw: the buffer holds one view, so its size does not grow
  // with the batch (a compute step per sphere where the vertex shader
  // placed each of the 4 corners itself).
  void plan_patch_corners(FrameContext& ctx, SlimResources& slim, int view) {
    const bool multi = view >= 0;
    ProgramPair& plan = programs_.get("slim_patch_plan");
    glUseProgram(plan.get(multi));
    const auto n = static_cast<GLint>(slim.sphere_count());
    glUniform1i(plan.uniform(multi, "u_count"), n);
    glUniform1i(plan.uniform(multi, "u_cull_backfaces"), ctx.scene.slim.cull_backfaces ? 1 : 0);
    glUniform1f(plan.uniform(multi, "u_threshold"),
                static_cast<float>(ctx.scene.slim.depth_threshold));
    if (multi) glUniform1i(plan.uniform(true, "u_view"), view);
    set_view_offset(ctx, plan.uniform(multi, "u_offset"), view, slim.anchor());
    dispatch_compute(static_cast<GLuint>((n + 63) / 64), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  }

  bool depth_;
  LazyPrograms programs_;
  QuadIndices quads_;
};

// Pass 3: normalization into the surfaces' targets.
class SlimResolvePass final : public Pass {
 public:
  explicit SlimResolvePass(bool gbuffer) : program_("slim_resolve"), gbuffer_(gbuffer) {}
  void execute(FrameContext& ctx, const PassDecl& self) override {
    if (!ctx.resources.slim() || ctx.resources.slim()->sphere_count() == 0) return;
    const bool multi = ctx.views > 0;
    glUseProgram(program_.get(multi));
    glUniform1i(program_.uniform(multi, "u_gi"), gbuffer_ ? 1 : 0);
    glUniform1i(program_.uniform(multi, "u_field"),
                ctx.scene.slim.evaluation != SlimEvaluation::kBlend ? 1 : 0);
    glBindTextureUnit(1, ctx.targets.texture(TargetId::kSlimSumAlbedo));
    glBindTextureUnit(2, ctx.targets.texture(TargetId::kSlimSumField));
    glBindTextureUnit(3, ctx.targets.texture(TargetId::kSlimSumWeight));
    glBindTextureUnit(4, ctx.targets.texture(TargetId::kSlimNear));
    glBindTextureUnit(5, ctx.targets.texture(TargetId::kSlimSumField2));
    glBindTextureUnit(6, ctx.targets.texture(TargetId::kSlimSumWeight2));
    glBindTextureUnit(7, ctx.targets.texture(TargetId::kSlimRadius));
    glUniform1f(program_.uniform(multi, "u_step"), kSlimFieldStep);
    glDisable(GL_BLEND);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glBindVertexArray(ctx.empty_vao);
    int view = 0;
    for_each_view(ctx, self, program_, [&] {
      scissor_to_slim(ctx, *ctx.resources.slim(), multi ? view++ : -1);
      draw_arrays(GL_TRIANGLES, 0, 3);
    });
    glDisable(GL_SCISSOR_TEST);
    gl_check("slim_resolve pass");
  }

 private:
  ProgramPair program_;
  bool gbuffer_;  // the "slim_gbuffer" row: into a lit scene's G-buffer
};

}  // namespace

std::unique_ptr<Pass> make_slim_depth_pass() { return std::make_unique<SlimPointsPass>(true); }
std::unique_ptr<Pass> make_slim_accumulate_pass() { return std::make_unique<SlimPointsPass>(false); }
std::unique_ptr<Pass> make_slim_resolve_pass(bool gbuffer) {
  return std::make_unique<SlimResolvePass>(gbuffer);
}

}  // namespace beamcast
