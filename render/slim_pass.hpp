// SLIM surfaces on the GPU (seed 003, issue 16): the support spheres in a
// buffer, each frame's sampling plan per sphere and view (grid size from the
// sphere's projected size), and the executors of the four slim passes of the
// pass graph (render/pass_plan.cpp): slim_depth, slim_accumulate and
// slim_resolve / slim_gbuffer.
//
// Sampling: sphere i of radius r whose projection is N pixels wide (at its
// centre's depth) is
// sampled on the (u, v) grid over [-r, r]^2 with step n = S r / N (S =
// slim.sampling), i.e. m = ceil(2N / S) samples a side, each the point
// (u, v, f(u, v)) of its local height field; points outside the sphere
// (weight 0) are dropped. The seed's second stage (slim.fill_holes): a cell
// whose neighbouring samples project more than a pixel apart gets L x L
// samples, L = ceil(the cell's longer projected diagonal / (sqrt(3) / 2)),
// which bounds every pixel centre's distance to a sample by half a pixel
// within the patch. Points are drawn with glMultiDrawArraysIndirect, one
// command per sphere (its sample count; 0 when the sphere is culled).
//
// slim.evaluation "patch" (the default) samples nothing: each sphere is one
// rectangle facing the eye that bounds its patch (placed by
// slim_patch_plan.comp, drawn by slim_patch.vert), whose
// fragments solve where their centre ray meets the height field
// (slim_patch.glsl); the accumulate pass first writes slim_near into a
// depth buffer (slim_zbuf) so that patches lying wholly behind the
// threshold fail the early depth test.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "protocol/camera.hpp"
#include "protocol/scene.hpp"
#include "render/gl_util.hpp"
#include "render/pass_plan.hpp"
#include "render/scene_gpu_cache.hpp"

namespace beamcast {

class Pass;

// The most samples a side of one sphere's grid, and the most second-stage
// samples a side of one cell: a sphere crossing the near plane projects
// without bound, and is sampled at most 2048 x 2048 x 4 x 4.
inline constexpr int kSlimMaxGrid = 2048;
inline constexpr int kSlimMaxFill = 4;

// One sphere's sampling in one view: m samples a side, up to s x s per cell
// (s = 1 without the second stage); m = 0: culled.
struct SlimGrid {
  std::uint32_t m = 0;
  std::uint32_t s = 1;
};

// The second stage splits a cell whose projected diagonal exceeds this
// (pixels): sqrt(3)/2 for the seed's blend (every pixel centre inside a
// patch then has a sample in its pixel), 6 for the field evaluation (whose
// points are drawn as wide as their cells: it bounds their size).
double slim_cell_diagonal(const SlimSettings& settings);

// The grid of `sphere` for a camera (CPU, double): culled (m = 0) when the
// sphere lies outside the view frustum; else as described above, with s the
// most second-stage samples a side any cell needs, from the projected cells
// at 7 x 7 places over the sphere (10% margin).
SlimGrid slim_grid(const SlimSphere& sphere, const Camera& cam, const CameraBasis& basis,
                   const SlimSettings& settings);

// What SlimResources uploads from the scene's content alone (the sphere
// records, their order, the instance array): a SceneGpuCache entry. Holds
// the surfaces its sphere pointers point into.
struct SlimStatic {
  std::vector<std::shared_ptr<const SlimSurface>> surfaces;
  std::vector<const SlimSphere*> spheres;
  std::size_t crease_begin = 0;
  Vec3 anchor{};
  Aabb box;
  GlBuffer sphere_ssbo, index_vbo;
  GlVertexArray vao;
  std::size_t bytes = 0;  // what the buffers hold
};

// GPU data of a scene's SLIM surfaces (upload group "slim").
class SlimResources {
 public:
  // `content`: where the sphere records are kept across renders, by the
  // surfaces' content, their materials and the evaluation (null: made for
  // this render alone).
  explicit SlimResources(const Scene& scene, SceneGpuCache* content = nullptr);
  std::size_t sphere_count() const { return st_->spheres.size(); }
  // The spheres are held with every crease sphere after every other one:
  // spheres [0, crease_begin()) have one polynomial, the rest a min/max of
  // two, so the patch evaluation draws each run with its own program (no
  // crease rule where none is needed: llvmpipe runs a fragment shader's
  // untaken branches too).
  std::size_t crease_begin() const { return st_->crease_begin; }
  GLuint sphere_buffer() const { return st_->sphere_ssbo.get(); }
  GLuint instance_vao() const { return st_->vao.get(); }
  const Vec3& anchor() const { return st_->anchor; }
  // The union of the SLIM surfaces' bounds (world space).
  const Aabb& bounds() const { return st_->box; }
  // The key of the scene's SLIM records in SceneGpuCache.
  static std::string content_key(const Scene& scene);

  // Plans the samples of `views` cameras (one command and one grid per
  // sphere and view, view-major) and uploads them; returns the sample slots
  // of each view (what the draws process; culled slots included).
  void plan_views(const std::vector<Camera>& cams, const std::vector<CameraBasis>& bases,
                  const SlimSettings& settings);
  // slim.evaluation "patch" draws one quad per sphere and view, planned on
  // the GPU (slim_patch_plan.comp writes a view's 4 corners a sphere into
  // corner_buffer() before each pass draws that view): here the slots are
  // recorded (one a sphere) and the corner buffer made.
  void plan_patches(std::size_t views);
  GLuint corner_buffer() const { return corner_ssbo_.get(); }
  GLuint command_buffer() const { return command_buffer_.get(); }
  GLuint grid_buffer() const { return grid_ssbo_.get(); }
  // Sample slots drawn per frame in the last plan_views (each view's sum).
  const std::vector<std::int64_t>& slots() const { return slots_; }

 private:
  static std::shared_ptr<const SlimStatic> make_static(const Scene& scene);
  std::shared_ptr<const SlimStatic> st_;
  GlBuffer command_buffer_, grid_ssbo_, corner_ssbo_;
  std::size_t capacity_views_ = 0;
  std::vector<std::int64_t> slots_;
};

// The executors of the slim passes (rows in render/pass_catalog.cpp):
// "slim_depth", "slim_accumulate", and "slim_resolve" (gbuffer false) or
// "slim_gbuffer" (true).
std::unique_ptr<Pass> make_slim_depth_pass();
std::unique_ptr<Pass> make_slim_accumulate_pass();
std::unique_ptr<Pass> make_slim_resolve_pass(bool gbuffer);

}  // namespace beamcast
