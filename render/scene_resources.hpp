// GPU resources of one scene: line-integral tables (one texture layer per
// distinct density), beam instance data and occluder geometry. Built once per
// scene and shared by all its cameras; per-camera data (camera-relative
// positions, the camera block) is refreshed by `bind_camera`.
#pragma once

#include <cstddef>
#include <list>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "gi/gi_scene.hpp"
#include "gi/photon_cache.hpp"
#include "protocol/camera.hpp"
#include "protocol/scene.hpp"
#include "render/gl_util.hpp"
#include "render/scene_gpu_cache.hpp"
#include "render/lut.hpp"
#include "render/pass_plan.hpp"
#include "render/slim_pass.hpp"
#include "render/specular_gpu.hpp"
#include "render/volume_grid.hpp"
#include "render/volume_pass.hpp"

namespace beamcast {

// Whether beam `g` (BeamGpu, camera-relative) is drawn as one full-screen
// triangle rather than its box: a perspective camera whose eye is inside
// the box or within twice the near plane's corner distance of it. There the
// box's faces are clipped at w = 0 and a pixel can fall between the pieces
// (NVIDIA, fov 178.4 deg, near 1e-4: stability sweep 55288); the fragment
// shader's exact ray test makes the larger cover correct.
bool beam_proxy_full_screen(const BeamGpu& g, double radius, const Camera& cam,
                            const CameraBasis& basis);

// CPU tables by (density, size), least recently used evicted first.
class TableCache {
 public:
  explicit TableCache(std::size_t max_entries) : max_entries_(max_entries) {}
  // `moments`: with the moment channels (LineIntegralTable::gm) of scenes
  // with a medium; a table with them serves requests without them too.
  std::shared_ptr<const LineIntegralTable> get(const Density& density, int nd, int ns, int nf,
                                               TableLayout layout, bool moments = false);

 private:
  std::size_t max_entries_;
  std::list<std::pair<std::string, std::shared_ptr<const LineIntegralTable>>> entries_;
};

// Triangle occluders (and lit scenes' quad-light emitters) as one vertex
// buffer, positions relative to `anchor`: a SceneGpuCache entry.
struct OccluderGeometry {
  GlBuffer vbo;
  GlVertexArray vao;
  GLsizei vertices = 0;
  Vec3 anchor{};
  Aabb bounds;
};

class SceneResources {
 public:
  // Uploads the resource groups the plan's passes declare (UploadGroup):
  // kBeams (tables, beam instances), kOccluders (triangles, analytic
  // occluders), kPhotons (the scene's photon maps from `photons`, traced
  // there unless cached), and so on.
  // `content`: where uploads that depend only on the scene's content are
  // kept across renders (null: made for this render alone).
  SceneResources(const Scene& scene, TableCache& tables, const FramePlan& plan,
                 PhotonCache* photons = nullptr, VolumeTextureCache* volumes = nullptr,
                 SceneGpuCache* content = nullptr);
  // Uploads the camera block and camera-relative beam and occluder data.
  void bind_camera(const Camera& cam, const CameraBasis& basis);
  // Multi-view: uploads one camera block per view (the CameraBlocks uniform
  // buffer, room for `max_views`) and view-major camera-relative beams and analytic occluders,
  // the same values bind_camera computes for each camera alone. Until the next
  // bind_camera, beam_buffer() and analytic_buffer() return the multi-view ones.
  void bind_views(const std::vector<Camera>& cams, const std::vector<CameraBasis>& bases,
                  int max_views);
  GLuint views_camera_buffer() const { return views_camera_ubo_.get(); }

  int table_d() const { return nd_; }
  int table_s() const { return ns_; }
  int table_f() const { return nf_; }
  GLuint g_texture() const { return g_tex_.get(); }
  // (g, G1, G2, G3) per texel, RGBA; 0 unless the scene has a medium.
  GLuint moment_texture() const { return gm_tex_.get(); }
  GLuint f_texture() const { return f_tex_.get(); }
  GLuint warp_texture() const { return warp_tex_.get(); }
  int warp_size() const { return nw_; }
  GLuint beam_buffer() const { return views_ ? views_beam_ssbo_.get() : beam_ssbo_.get(); }
  GLsizei beam_count() const { return static_cast<GLsizei>(beam_layers_.size()); }
  GLuint camera_buffer() const { return camera_ubo_.get(); }
  GLuint triangle_vao() const { return geometry_ ? geometry_->vao.get() : 0; }
  GLsizei triangle_vertex_count() const { return geometry_ ? geometry_->vertices : 0; }
  GLuint analytic_buffer() const {
    return views_ ? views_analytic_ssbo_.get() : analytic_ssbo_.get();
  }
  GLsizei analytic_count() const { return static_cast<GLsizei>(analytic_.size()); }
  // Photons (both maps), positions relative to photon_anchor().
  GLuint photon_buffer() const { return photon_ssbo_.get(); }
  // Disks in photon_buffer() (the drawn share of the maps, clustered by
  // gi.cluster), and the photons they hold (both maps, without those
  // straight from the lights when the direct pass carries direct light).
  GLsizei photon_count() const {
    return disks_ ? static_cast<GLsizei>(disks_->disks.size()) : 0;
  }
  std::int64_t photons_kept() const { return disks_ ? disks_->photons : 0; }
  const Vec3& photon_anchor() const { return disks_ ? disks_->anchor : kOrigin; }
  double photon_radius() const { return photon_radius_; }
  // The photon buffer holds the global map's photons, then from this index
  // the caustic map's, splatted with caustic_radius().
  GLsizei photon_caustic_first() const {
    return disks_ ? static_cast<GLsizei>(disks_->caustic_first) : 0;
  }
  double caustic_radius() const { return caustic_radius_; }
  // Volume photons (group "volume_photons": the medium's scattering events of
  // the global map), positions relative to volume_anchor(), the photon's
  // travel direction in the normal slot; volume_radius() their kernel radius.
  GLuint volume_buffer() const { return volume_ssbo_.get(); }
  GLsizei volume_count() const { return volume_count_; }
  const Vec3& volume_anchor() const { return volume_anchor_; }
  double volume_radius() const { return volume_radius_; }
  // The same photons binned into a world grid (group "volume_grid",
  // render/volume_grid.hpp); null without that group.
  const VolumeGridResources* volume_grid() const { return volume_grid_.get(); }
  // Direct light (group "shadows"): the lights' DirectPoints, each with its
  // light's flux folded in, positions relative to direct_anchor(); the key
  // names the geometry and points the shadow maps are rendered for.
  GLuint direct_buffer() const { return direct_ssbo_.get(); }
  const std::vector<DirectPoint>& direct_points() const { return direct_points_; }
  const Vec3& direct_anchor() const { return direct_anchor_; }
  // The first direct_interleaved() points (a multiple of 4: the lights with a
  // multiple of 4 points, with gi.direct_interleave 4) are shared out over
  // the 2 x 2 pixel pattern; the rest are summed at every pixel.
  int direct_interleaved() const { return direct_interleaved_; }
  const std::string& shadow_key() const { return shadow_key_; }
  // The triangle vertices' anchor (positions in triangle_vao() are relative to it).
  const Vec3& mesh_anchor() const { return mesh_anchor_; }
  const Aabb& mesh_bounds() const { return mesh_bounds_; }
  // The key of the scene's occluder triangles in SceneGpuCache (their content).
  static std::string occluder_key(const Scene& scene);
  // Ray tracing on the CPU (group "specular"): the scene's surfaces and its
  // photon maps' search structures; null without the group.
  const GiScene* gi_scene() const { return gi_scene_.get(); }
  const PhotonGather* photon_gather() const { return photon_gather_.get(); }
  // The same on the GPU (render/specular_gpu.hpp), instead of the two
  // above, with gi.specular_tracer "gpu" where gpu_traces_specular.
  const SpecularGpu* specular_gpu() const { return specular_gpu_.get(); }
  // The mesh regions' triangles (Scene::media), world space, three vec4 per
  // triangle in the regions' order, for shaders/medium_regions.glsl; 0
  // without mesh regions.
  GLuint medium_triangle_buffer() const { return medium_tri_ssbo_.get(); }
  // SLIM surfaces (group "slim"); null without them.
  SlimResources* slim() const { return slim_.get(); }
  // Scalar volumes (group "volumes"); null without them.
  const VolumeResources* volumes() const { return volumes_.get(); }
  // Time spent tracing the maps for this render (0 when they came from the
  // cache) and uploading them.
  double photon_trace_ms() const { return photon_trace_ms_; }
  double photon_upload_ms() const { return photon_upload_ms_; }

 private:
  const Scene& scene_;
  int nd_ = 0, ns_ = 0, nf_ = 0, nw_ = 2;
  std::vector<float> beam_layers_;  // table layer of each beam
  GlTexture g_tex_, f_tex_, warp_tex_, gm_tex_;
  GlBuffer beam_ssbo_, camera_ubo_, analytic_ssbo_;
  std::shared_ptr<const OccluderGeometry> geometry_;  // null without triangles
  Vec3 mesh_anchor_{};
  Aabb mesh_bounds_;
  std::vector<const Occluder*> analytic_;  // planes and spheres
  bool views_ = false;  // bind_views was last
  GlBuffer views_camera_ubo_, views_beam_ssbo_, views_analytic_ssbo_;
  std::size_t views_capacity_ = 0;  // views the multi-view buffers hold

  void upload_beams(TableCache& tables);
  void upload_occluders(SceneGpuCache* content);
  std::shared_ptr<const OccluderGeometry> make_geometry() const;
  void upload_photons(PhotonCache& cache, bool skip_direct);
  void upload_volume_photons(PhotonCache& cache);
  void upload_volume_grid(PhotonCache& cache);
  // The volume photons' kernel radius: medium.radius or the default for
  // the drawn share of `stored` photons.
  double volume_kernel_radius(std::size_t stored) const;
  void upload_direct();
  GlBuffer direct_ssbo_;
  GlBuffer medium_tri_ssbo_;
  void upload_medium_meshes();
  void upload_specular(PhotonCache& photons, bool shadows);
  std::vector<DirectPoint> direct_points_;
  std::vector<Color> direct_flux_;  // each point's light's flux
  int direct_interleaved_ = 0;
  Vec3 direct_anchor_{};
  std::string shadow_key_;
  std::shared_ptr<const PhotonMaps> maps_;
  GlBuffer photon_ssbo_;
  static constexpr Vec3 kOrigin{0.0, 0.0, 0.0};
  std::shared_ptr<const SplatDiskSet> disks_;  // what photon_ssbo_ holds (cached with the maps)
  double photon_radius_ = 1.0;
  double caustic_radius_ = 1.0;
  double photon_trace_ms_ = 0.0;
  double photon_upload_ms_ = 0.0;
  GlBuffer volume_ssbo_;
  GLsizei volume_count_ = 0;
  Vec3 volume_anchor_{};
  double volume_radius_ = 1.0;
  std::unique_ptr<VolumeGridResources> volume_grid_;
  std::unique_ptr<SlimResources> slim_;
  std::unique_ptr<VolumeResources> volumes_;
  std::unique_ptr<GiScene> gi_scene_;
  std::shared_ptr<const PhotonGather> photon_gather_;
  std::unique_ptr<SpecularGpu> specular_gpu_;
  // The per-camera data of bind_camera, written to `out` (for bind_views).
  void fill_camera(const Camera& cam, const CameraBasis& basis, void* block) const;
  void fill_beams(const Camera& cam, const CameraBasis& basis, void* beams) const;
  void fill_analytic(const Vec3& eye, void* analytic) const;
};

}  // namespace beamcast
