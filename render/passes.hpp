// What pass executors share: the frame's targets, the frame context, the
// Pass interface and the helpers executors draw with. A new effect (photon
// splatting, media, point surfaces, volumes) is a row in pass_catalog.cpp
// (rule, targets, uploads, executor factory) and its executor's own file,
// which includes this one; the frame loop does not change.
#pragma once

#include <algorithm>
#include <array>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/camera.hpp"
#include "protocol/scene.hpp"
#include "render/gl_util.hpp"
#include "render/pass_plan.hpp"
#include "render/scene_resources.hpp"
#include "shaders/shader_sources.hpp"

namespace beamcast {

// The render targets of one frame size, allocated from plans: a target is
// allocated the first time a plan uses it (read or written by a planned pass)
// and kept for later frames of the same sizes; one framebuffer per pass (its
// declared writes: colour attachments in order, then depth) is made when the
// pass first runs. With layers > 0 every target is a 2D array texture of that
// many layers (one per view of a multi-view batch), with one framebuffer per
// pass and layer.
class FrameTargets {
 public:
  static constexpr float kNoSurface = 1e30f;
  // Sizes: render (camera x resolution scale) and camera (the client's size).
  // A change of size, bit depth or layer count frees everything first.
  void ensure(const FramePlan& plan, int render_w, int render_h, int camera_w, int camera_h,
              int bits, int layer_count = 0);
  // Clears every cleared target of the plan (all layers) to its start value.
  void clear(const FramePlan& plan, const Color& background);
  // The texture of `target`; throws GlError if this frame's plan did not
  // allocate it (a pass reading a target it did not declare).
  GLuint texture(TargetId target) const;
  // A 1x1 (x1 layer) R32F texture of `target` holding 0, for a sampler that
  // a program has compiled in but does not read in this frame: the spec
  // leaves sampling unit with no texture undefined (GL 4.5 core 8.17).
  GLuint placeholder(GLenum target);
  // The framebuffer of `pass` for `view` (view < 0 or no layers: the plain one).
  GLuint fbo(const PassDecl& pass, int view);
  int layers() const { return layers_; }
  // The divisor of the kSplat targets as allocated: the plan's, or with the
  // plan's 0 (gi.splat_scale "auto") auto_splat_scale of the render size.
  int splat_scale() const { return splat_scale_; }
  // How the kSplat targets' texels are laid out (SplatBands).
  const SplatBands& splat_bands() const { return splat_bands_; }

 private:
  struct Target {
    const TargetDecl* decl = nullptr;
    GlTexture texture;
  };
  struct PassFbos {
    GlFramebuffer plain;
    std::vector<GlFramebuffer> per_layer;
  };
  int render_w_ = 0, render_h_ = 0, camera_w_ = 0, camera_h_ = 0, bits_ = 0, layers_ = 0;
  int splat_scale_ = 1;
  SplatBands splat_bands_;
  std::array<Target, kTargetCount> targets_{};  // by TargetId; decl null: not allocated
  std::map<const PassDecl*, PassFbos> fbos_;     // by catalog row
  std::map<GLenum, GlTexture> placeholders_;  // by target; kept across sizes
  const Target* find(TargetId id) const;
  GLuint make_fbo(const PassDecl& pass, int layer);
};

struct FrameContext {
  const Scene& scene;
  const FramePlan& plan;
  const Camera& camera;
  const CameraBasis& basis;
  SceneResources& resources;
  FrameTargets& targets;
  GLuint empty_vao;
  // 0: one camera (`camera`), the per-camera programs. K >= 1: a multi-view
  // batch of K <= kMaxBatchViews views (SceneResources::bind_views, array
  // targets), drawn by the multi-view programs, each draw once per view into
  // that view's layer with the uniform u_view; `camera` is the first.
  int views = 0;
  // The camera's own size (`camera` is at the render size; they differ only
  // for scaled frames, which the upscale pass brings back to this size).
  int output_width = 0;
  int output_height = 0;
  // Multi-view: each view's eye (world, double), for passes that place
  // world-anchored data relative to it.
  std::vector<Vec3> view_eyes;
  // Multi-view: each view's camera and basis (at the render size).
  const std::vector<Camera>* view_cameras = nullptr;
  const std::vector<CameraBasis>* view_bases = nullptr;
};


// The size of a TargetSize::kSplat target for a render size.
inline int splat_size(int render_size, int scale) { return (render_size + scale - 1) / scale; }
// gi.splat_scale 0 (the default): 8 from 512 render pixels a side (the
// smaller side) up, else 4. On the Cornell box at 512^2 8 has 4's error
// within 0.1% per wall at 0.85x its GPU time on llvmpipe (docs/gi.md);
// below 512 the splat grid would fall under 64 texels a side. With a
// caustic map, FramePlan::auto_splat_cap bounds it (FrameTargets::ensure).
inline int auto_splat_scale(int render_w, int render_h) {
  return std::min(render_w, render_h) >= 512 ? 8 : 4;
}

// How a declared pass (PassDecl) executes. `self` is its declaration (its
// targets' framebuffers come from ctx.targets.fbo(self, view)).
class Pass {
 public:
  virtual ~Pass() = default;
  virtual void execute(FrameContext& ctx, const PassDecl& self) = 0;
};

// A program of shaders/programs.txt in its per-camera and its multi-view
// variant (the latter built on first use; see shaders/multiview.glsl).
class ProgramPair {
 public:
  explicit ProgramPair(std::string name) : name_(std::move(name)) {
    single_ = build(shader_program(name_));
  }
  GLuint get(bool multiview) {
    if (!multiview) return single_.get();
    if (!multi_) multi_ = build(shader_program(name_ + "_multiview"));
    return multi_.get();
  }
  GLint uniform(bool multiview, const char* name) {
    return glGetUniformLocation(get(multiview), name);
  }

 private:
  static GlProgram build(const ShaderProgramSpec& spec) {
    if (!spec.compute.empty()) return build_compute_program(spec.name, assemble_shader(spec.compute));
    return build_program(spec.name, assemble_shader(spec.vertex), assemble_shader(spec.fragment));
  }
  std::string name_;
  GlProgram single_, multi_;
};

// A pass's compile-time variants of a program (shaders/programs.txt names
// each one), each built on first use: a renderer compiles only those its
// scenes need. Variants stand in for uniform branches, which llvmpipe pays
// for even where they are never taken (docs/volumes.md, "Speed").
class LazyPrograms {
 public:
  ProgramPair& get(const std::string& name) {
    auto it = programs_.find(name);
    if (it == programs_.end()) {
      it = programs_.emplace(name, std::make_unique<ProgramPair>(name)).first;
    }
    return *it->second;
  }

 private:
  std::map<std::string, std::unique_ptr<ProgramPair>> programs_;
};

// The program-name suffix of a splatting kernel (shaders/gi_kernel_*.glsl;
// Epanechnikov, the default, has none).
inline const char* kernel_suffix(SplatKernel k) {
  return k == SplatKernel::kBox ? "_box" : k == SplatKernel::kCone ? "_cone" : "";
}

// A program and its "<name>_regions" variant (shaders/medium_regions.glsl
// compiled in, for scenes with regions of medium; built on first use).
class RegionProgram {
 public:
  explicit RegionProgram(std::string name) : plain_(name), name_(std::move(name)) {}
  ProgramPair& get(const Scene& scene) {
    if (scene.media.empty()) return plain_;
    if (!regions_) regions_.emplace(name_ + "_regions");
    return *regions_;
  }

 private:
  ProgramPair plain_;
  std::string name_;
  std::optional<ProgramPair> regions_;
};

// Issues `draw` into `fbo(view)` once per view of a multi-view batch (with
// u_view = the view), or once into the plain framebuffer for a single camera.
template <class Draw>
void for_each_view(FrameContext& ctx, const PassDecl& self, ProgramPair& program, Draw draw) {
  if (ctx.views == 0) {
    glBindFramebuffer(GL_FRAMEBUFFER, ctx.targets.fbo(self, -1));
    draw();
    return;
  }
  const GLint loc = program.uniform(true, "u_view");
  for (int v = 0; v < ctx.views; ++v) {
    glBindFramebuffer(GL_FRAMEBUFFER, ctx.targets.fbo(self, v));
    glUniform1i(loc, v);
    draw();
  }
}

// The eye of view `view` of a multi-view batch, or (single camera, or
// view < 0) the camera's.
const Vec3& view_eye(const FrameContext& ctx, int view);
// `anchor` minus view `view`'s eye (in double, then float) into the vec3
// uniform at `location` of the bound program: world-anchored data drawn
// relative to the eye.
void set_view_offset(const FrameContext& ctx, GLint location, int view, const Vec3& anchor);

// for_each_view for draws of world-anchored data: before each view's draw
// the uniform `offset_uniform` gets `anchor` minus that view's eye
// (set_view_offset).
template <class Draw>
void for_each_view_offset(FrameContext& ctx, const PassDecl& self, ProgramPair& program,
                          const char* offset_uniform, const Vec3& anchor, Draw draw) {
  const bool multi = ctx.views > 0;
  const GLint offset = program.uniform(multi, offset_uniform);
  int v = 0;
  for_each_view(ctx, self, program, [&] {
    set_view_offset(ctx, offset, multi ? v++ : -1, anchor);
    draw();
  });
}

// The medium's uniforms: u_sigma_t (the scene-wide medium's extinction, 0
// without one) and the regions of shaders/medium_regions.glsl (Scene::media,
// at most kMaxMediumRegions; mesh regions' triangles from the scene
// resources, SSBO binding 7); returns the location of u_region_eye, which
// each view's draw sets with set_region_eye.
GLint set_medium_uniforms(ProgramPair& program, bool multiview, const FrameContext& ctx);
// The eye of view `view` (-1 or the only view: ctx.basis.eye) into u_region_eye.
void set_region_eye(const FrameContext& ctx, GLint location, int view);

// Additive draws into hdr: blending ONE + ONE, no depth test, no culling,
// and the empty vertex array of full-screen and generated draws bound.
void begin_additive(const FrameContext& ctx);
// The G-buffer of lit scenes on texture units 0-2: view_depth, gb_normal,
// gb_albedo (the binding order of the lighting passes' shaders).
void bind_gbuffer(const FrameContext& ctx);

// Binds the view-sized target `name` (VIEW_SAMPLER: sampler2D, or
// sampler2DArray in multi-view batches) to `unit` if a planned pass writes
// it, else that sampler's placeholder (FrameTargets::placeholder). Returns
// whether the target is there.
bool bind_view_target_or_placeholder(FrameContext& ctx, GLuint unit, TargetId target);
// The VIEW_SAMPLER placeholder alone, for a sampler compiled in but unread.
void bind_view_placeholder(FrameContext& ctx, GLuint unit);

// The photon LOD uniforms of shaders/photon_splat.vert (GiSettings::lod_*),
// for the passes that draw photons with it.
void set_photon_lod(ProgramPair& program, bool multiview, const GiSettings& gi);

// A rectangle of pixels, lower-left and upper-right inclusive, in window
// coordinates (y up); kEveryPixel: no bound.
inline constexpr std::array<int, 4> kEveryPixel = {-(1 << 30), -(1 << 30), 1 << 30, 1 << 30};
// The pixels the projections of `points` can touch, `margin` pixels wider on
// each side (their convex hull's projection when every point lies in front
// of the near plane); kEveryPixel if a point has no place in the image (at
// or behind the near plane's depth).
std::array<int, 4> pixel_rect(std::span<const Vec3> points, const Camera& cam, const CameraBasis& b,
                              int margin);

}  // namespace beamcast
