#include "render/scene_resources.hpp"

#include "protocol/scene_bounds.hpp"

#include <chrono>
#include <type_traits>

#include <algorithm>
#include <cmath>
#include <limits>

namespace beamcast {

std::shared_ptr<const LineIntegralTable> TableCache::get(const Density& density, int nd, int ns,
                                                         int nf, TableLayout layout,
                                                         bool moments) {
  const std::string key = density.key() + "|" + std::to_string(nd) + "x" + std::to_string(ns) +
                          "|" + std::to_string(nf) + "|" +
                          std::to_string(static_cast<int>(layout));
  for (auto it = entries_.begin(); it != entries_.end(); ++it) {
    if (it->first == key && (!moments || !it->second->gm.empty())) {
      entries_.splice(entries_.begin(), entries_, it);  // most recently used first
      return entries_.front().second;
    }
  }
  auto table = std::make_shared<const LineIntegralTable>(
      build_table(density, nd, ns, nf, layout, moments));
  // A table with moments replaces the one without.
  entries_.remove_if([&](const auto& e) { return e.first == key; });
  entries_.emplace_front(key, table);
  while (entries_.size() > max_entries_) entries_.pop_back();
  return table;
}

std::shared_ptr<const void> SceneGpuCache::find_entry(const std::string& key) {
  const auto it = index_.find(key);
  if (it == index_.end()) {
    ++misses_;
    return nullptr;
  }
  ++hits_;
  lru_.splice(lru_.begin(), lru_, it->second);
  return it->second->value;
}

void SceneGpuCache::put(const std::string& key, std::shared_ptr<const void> value,
                        std::size_t bytes) {
  if (const auto it = index_.find(key); it != index_.end()) {
    bytes_ -= it->second->bytes;
    lru_.erase(it->second);
    index_.erase(it);
  }
  if (bytes > budget_) return;
  lru_.push_front(Entry{key, std::move(value), bytes});
  index_[key] = lru_.begin();
  bytes_ += bytes;
  shrink_to(budget_);
}

void SceneGpuCache::shrink_to(std::size_t bytes) {
  while (bytes_ > bytes && !lru_.empty()) {
    bytes_ -= lru_.back().bytes;
    index_.erase(lru_.back().key);
    lru_.pop_back();
    ++evictions_;
  }
}

SceneGpuCache::Stats SceneGpuCache::stats() const {
  return {bytes_, lru_.size(), budget_, hits_, misses_, evictions_};
}

namespace {

struct alignas(16) CameraBlock {
  float view_proj[16];  // column-major
  float right[4];
  float up[4];
  float forward[4];
  float viewport[4];
  float light_dir[4];
  float light_color[4];
  float mesh_offset[4];
};

struct alignas(16) BeamData {
  float p0_radius[4];
  float axis_length[4];
  float color_layer[4];
  float caps_kind[4];
  float density[4];
};

struct alignas(16) AnalyticData {
  float a[4];
  float b[4];
  float albedo[4];
};

// The G-buffer's material code of an emitter (after the MaterialType values
// 0 diffuse, 1 mirror, 2 glass); shaders/surface.frag.
constexpr float kEmitterMaterial = 3.0f;

struct Vertex {
  float position[3];
  float normal[3];
  float albedo[3];
  float one_sided;  // 1: drawn only from the side the normal points to
  float material;   // MaterialType (the G-buffer of lit scenes)
};

void set3(float* dst, const Vec3& v, float w) {
  dst[0] = static_cast<float>(v[0]);
  dst[1] = static_cast<float>(v[1]);
  dst[2] = static_cast<float>(v[2]);
  dst[3] = w;
}

// Camera-relative view-projection with reversed Z (near -> 1, far -> 0), in
// double, column-major. View rows are right, up, -forward (no translation: the
// eye is the origin of camera-relative space).
void view_projection(const Camera& cam, const CameraBasis& b, float out[16]) {
  double p[4][4] = {};  // p[row][col] of projection
  const double n = cam.near_plane, f = cam.far_plane;
  if (cam.projection == Projection::kPerspective) {
    p[0][0] = 1.0 / (b.tan_half_fov * b.aspect);
    p[1][1] = 1.0 / b.tan_half_fov;
    p[2][2] = n / (f - n);
    p[2][3] = n * f / (f - n);
    p[3][2] = -1.0;
  } else {
    p[0][0] = 1.0 / (b.half_height * b.aspect);
    p[1][1] = 1.0 / b.half_height;
    p[2][2] = 1.0 / (f - n);
    p[2][3] = f / (f - n);
    p[3][3] = 1.0;
  }
  const Vec3 rows[3] = {b.right, b.up, -1.0 * b.forward};
  double view[4][4] = {};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) view[r][c] = rows[r][c];
  view[3][3] = 1.0;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      double s = 0.0;
      for (int k = 0; k < 4; ++k) s += p[r][k] * view[k][c];
      out[c * 4 + r] = static_cast<float>(s);
    }
  }
}

// Collects a triangles kind's triangles as flat-shaded vertices relative to
// `anchor`; degenerate triangles cover no pixel and are skipped.
class VertexSink final : public TriangleSink {
 public:
  VertexSink(const Vec3& anchor, std::vector<Vertex>* out) : anchor_(anchor), out_(out) {}
  Color albedo{};
  float material = 0.0f;
  void add(const Vec3& wa, const Vec3& wb, const Vec3& wc, bool one_sided) override {
    const Vec3 a = wa - anchor_, b = wb - anchor_, c = wc - anchor_;
    const Vec3 cr = cross(b - a, c - a);
    const double len = length(cr);
    if (!(len > 0.0)) return;
    const Vec3 n = (1.0 / len) * cr;
    for (const Vec3* p : {&a, &b, &c}) {
      Vertex v;
      for (int k = 0; k < 3; ++k) {
        v.position[k] = static_cast<float>((*p)[k]);
        v.normal[k] = static_cast<float>(n[k]);
        v.albedo[k] = static_cast<float>(albedo[k]);
      }
      v.one_sided = one_sided ? 1.0f : 0.0f;
      v.material = material;
      out_->push_back(v);
    }
  }

 private:
  Vec3 anchor_;
  std::vector<Vertex>* out_;
};

// Appends the triangles' exact values to a key.
class KeySink final : public TriangleSink {
 public:
  explicit KeySink(std::string* key) : key_(key) {}
  void add(const Vec3& a, const Vec3& b, const Vec3& c, bool one_sided) override {
    for (const Vec3* p : {&a, &b, &c}) {
      key_->append(reinterpret_cast<const char*>(p->data()), sizeof(Vec3));
    }
    key_->push_back(one_sided ? '1' : '0');
  }

 private:
  std::string* key_;
};

void append_raw(std::string* key, const Vec3& v) {
  key->append(reinterpret_cast<const char*>(v.data()), sizeof(Vec3));
}

}  // namespace

SceneResources::SceneResources(const Scene& scene, TableCache& tables, const FramePlan& plan,
                               PhotonCache* photons, VolumeTextureCache* volumes,
                               SceneGpuCache* content)
    : scene_(scene) {
  upload_medium_meshes();
  const bool shadows = plan.uploads_group(UploadGroup::kShadows);
  auto need = [&](const char* what) -> PhotonCache& {
    if (!photons) {
      throw GlError(std::string("the plan ") + what + " but the renderer has no photon cache");
    }
    return *photons;
  };
  // Every group the plan lists, in UploadGroup order (the switch has no
  // default: a new group without its upload does not compile, -Wswitch).
  for (std::size_t g = 0; g <= static_cast<std::size_t>(UploadGroup::kSpecular); ++g) {
    const auto group = static_cast<UploadGroup>(g);
    if (!plan.uploads_group(group)) continue;
    switch (group) {
      case UploadGroup::kBeams:
        upload_beams(tables);
        break;
      case UploadGroup::kOccluders:
        upload_occluders(content);
        break;
      case UploadGroup::kPhotons:
        // Photons straight from a light are left out when the direct pass
        // carries direct light.
        upload_photons(need("splats photons"), shadows);
        break;
      case UploadGroup::kVolumePhotons:
        upload_volume_photons(need("splats volume photons"));
        break;
      case UploadGroup::kVolumeGrid:
        upload_volume_grid(need("bins volume photons"));
        break;
      case UploadGroup::kShadows:
        upload_direct();
        break;
      case UploadGroup::kSlim:
        slim_ = std::make_unique<SlimResources>(scene, content);
        break;
      case UploadGroup::kVolumes:
        volumes_ = std::make_unique<VolumeResources>(scene, volumes);
        break;
      case UploadGroup::kSpecular:
        upload_specular(need("traces specular rays"), shadows);
        break;
    }
  }
  GLuint id = 0;
  glCreateBuffers(1, &id);
  camera_ubo_ = GlBuffer(id);
  glNamedBufferStorage(id, sizeof(CameraBlock), nullptr, GL_DYNAMIC_STORAGE_BIT);
  gl_check("create scene buffers");
}

void SceneResources::upload_specular(PhotonCache& photons, bool shadows) {
  const Scene& scene = scene_;
  if (!maps_) maps_ = photons.get(scene);
  const SpecularTracer tracer = scene.gi.specular_tracer;
  const bool gpu =
      tracer == SpecularTracer::kGpu || (tracer == SpecularTracer::kAuto && !software_gl());
  if (gpu && gpu_traces_specular(scene)) {
    specular_gpu_ = std::make_unique<SpecularGpu>(scene, *maps_, shadows);
  } else {
    gi_scene_ = std::make_unique<GiScene>(scene);
    photon_gather_ = photons.gather(maps_, shadows);
  }
}

void SceneResources::upload_medium_meshes() {
  std::vector<float> data;
  for (const MediumRegion& r : scene_.media) {
    for (const auto& t : r.gpu_triangles()) {
      for (const Vec3& p : t) {
        data.insert(data.end(), {static_cast<float>(p[0]), static_cast<float>(p[1]),
                                 static_cast<float>(p[2]), 0.0f});
      }
    }
  }
  if (data.empty()) return;
  GLuint id = 0;
  glCreateBuffers(1, &id);
  medium_tri_ssbo_ = GlBuffer(id);
  glNamedBufferStorage(id, static_cast<GLsizeiptr>(data.size() * sizeof(float)), data.data(), 0);
  gl_check("upload medium meshes");
}

void SceneResources::upload_beams(TableCache& tables) {
  const Scene& scene = scene_;
  nd_ = scene.render.table_d;
  ns_ = scene.render.table_s;
  nf_ = scene.render.f_table;

  // One table layer per distinct density.
  std::vector<std::shared_ptr<const LineIntegralTable>> layers;
  std::vector<std::string> keys;
  for (const Beam& beam : scene.beams) {
    const std::string key = beam.density.key();
    auto it = std::find(keys.begin(), keys.end(), key);
    if (it == keys.end()) {
      keys.push_back(key);
      layers.push_back(
          tables.get(beam.density, nd_, ns_, nf_, scene.render.layout, scene.has_medium()));
      it = keys.end() - 1;
    }
    beam_layers_.push_back(static_cast<float>(it - keys.begin()));
  }
  if (!layers.empty()) {
    const auto count = static_cast<GLsizei>(layers.size());
    GLuint id = 0;
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &id);
    g_tex_ = GlTexture(id);
    glTextureStorage3D(id, 1, GL_R32F, ns_, nd_, count);
    glCreateTextures(GL_TEXTURE_1D_ARRAY, 1, &id);
    f_tex_ = GlTexture(id);
    glTextureStorage2D(id, 1, GL_R32F, nf_, count);
    // Warped layouts carry W(d); others get a 2-texel identity so the binding
    // is always complete.
    nw_ = layers[0]->nw > 0 ? layers[0]->nw : 2;
    glCreateTextures(GL_TEXTURE_1D_ARRAY, 1, &id);
    warp_tex_ = GlTexture(id);
    glTextureStorage2D(id, 1, GL_R32F, nw_, count);
    glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    for (GLsizei i = 0; i < count; ++i) {
      glTextureSubImage3D(g_tex_.get(), 0, 0, 0, i, ns_, nd_, 1, GL_RED, GL_FLOAT,
                          layers[i]->g.data());
      glTextureSubImage2D(f_tex_.get(), 0, 0, i, nf_, 1, GL_RED, GL_FLOAT, layers[i]->f.data());
      const float identity[2] = {0.0f, 1.0f};
      glTextureSubImage2D(warp_tex_.get(), 0, 0, i, nw_, 1, GL_RED, GL_FLOAT,
                          layers[i]->warp.empty() ? identity : layers[i]->warp.data());
    }
    if (scene.has_medium()) {
      glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &id);
      gm_tex_ = GlTexture(id);
      glTextureStorage3D(id, 1, GL_RGBA32F, ns_, nd_, count);
      for (GLsizei i = 0; i < count; ++i) {
        glTextureSubImage3D(id, 0, 0, 0, i, ns_, nd_, 1, GL_RGBA, GL_FLOAT, layers[i]->gm.data());
      }
    }
    for (GLuint tex : {g_tex_.get(), f_tex_.get(), gm_tex_.get()}) {
      if (tex == 0) continue;
      glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glTextureParameteri(tex, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTextureParameteri(tex, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    gl_check("upload line-integral tables");
    glCreateBuffers(1, &id);
    beam_ssbo_ = GlBuffer(id);
    glNamedBufferStorage(id, static_cast<GLsizeiptr>(sizeof(BeamData) * scene.beams.size()),
                         nullptr, GL_DYNAMIC_STORAGE_BIT);
  }
}

// Both maps in one buffer (the splat pass draws them alike), positions
// relative to the centre of their bounds; photons straight from the lights
// are marked (position.w = 1).
void SceneResources::upload_photons(PhotonCache& cache, bool skip_direct) {
  bool traced = false;
  maps_ = cache.get(scene_, &traced);
  photon_trace_ms_ = traced ? maps_->trace_ms : 0.0;
  // Upload time from here: the maps may have been traced before the render
  // (FrameOptions::photon_maps), so their trace time is not part of get().
  const auto t0 = std::chrono::steady_clock::now();
  // A share of the maps drawn (gi.display_fraction, their first photons, power
  // scaled up): the default radii at the drawn photon counts. The disks
  // (clustered by gi.cluster) are kept with the maps.
  const SplatRadii radii = splat_radii(scene_, scene_.gi.display_fraction);
  photon_radius_ = radii.global;
  caustic_radius_ = radii.caustic;
  disks_ = cache.disks(maps_, {skip_direct, display_share(scene_.gi.display_fraction),
                               photon_radius_, caustic_radius_, scene_.gi.cluster});
  const std::vector<SplatDisk>& data = disks_->disks;
  if (!data.empty()) {
    GLuint id = 0;
    glCreateBuffers(1, &id);
    photon_ssbo_ = GlBuffer(id);
    glNamedBufferStorage(id, static_cast<GLsizeiptr>(data.size() * sizeof(SplatDisk)), data.data(), 0);
  }
  photon_upload_ms_ =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  gl_check("upload photons");
}

void SceneResources::upload_volume_photons(PhotonCache& cache) {
  if (!maps_) {
    bool traced = false;
    maps_ = cache.get(scene_, &traced);
    photon_trace_ms_ += traced ? maps_->trace_ms : 0.0;
  }
  const auto t0 = std::chrono::steady_clock::now();  // as in upload_photons
  Aabb box;
  for (const Photon& p : maps_->volume) box.grow(Vec3{p.p[0], p.p[1], p.p[2]});
  volume_anchor_ = box.empty() ? Vec3{0.0, 0.0, 0.0} : box.centre();
  struct VolumeData {
    float position[4];
    float power[4];
    float dir[4];
  };
  std::vector<VolumeData> data(maps_->volume.size());
  const MediumField field = scene_.medium_field();
  for (std::size_t i = 0; i < data.size(); ++i) {
    const Photon& p = maps_->volume[i];
    for (int k = 0; k < 3; ++k) {
      data[i].position[k] =
          static_cast<float>(p.p[k] - volume_anchor_[static_cast<std::size_t>(k)]);
      data[i].power[k] = p.power[k];
      data[i].dir[k] = p.dir[k];
    }
    // The phase parameter and extinction where the photon scattered.
    const Vec3 x{p.p[0], p.p[1], p.p[2]};
    data[i].position[3] = static_cast<float>(field.k(x));
    data[i].dir[3] = static_cast<float>(field.sigma_t(x));
  }
  volume_count_ = static_cast<GLsizei>(data.size());
  if (!data.empty()) {
    GLuint id = 0;
    glCreateBuffers(1, &id);
    volume_ssbo_ = GlBuffer(id);
    glNamedBufferStorage(id, static_cast<GLsizeiptr>(data.size() * sizeof(VolumeData)),
                         data.data(), 0);
  }
  volume_radius_ = volume_kernel_radius(maps_->volume.size());
  photon_upload_ms_ +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  gl_check("upload volume photons");
}

double SceneResources::volume_kernel_radius(std::size_t stored) const {
  // The drawn share (gi.display_fraction) sets the default radius, as for the surface maps.
  const double share = display_share(scene_.gi.display_fraction);
  const auto drawn =
      std::max<std::int64_t>(1, std::llround(share * static_cast<double>(stored)));
  return scene_.medium && scene_.medium->radius > 0.0 ? scene_.medium->radius
                                                      : default_volume_radius(scene_, drawn);
}

void SceneResources::upload_volume_grid(PhotonCache& cache) {
  const auto t0 = std::chrono::steady_clock::now();
  double traced_ms = 0.0;
  if (!maps_) {
    bool traced = false;
    maps_ = cache.get(scene_, &traced);
    traced_ms = traced ? maps_->trace_ms : 0.0;
    photon_trace_ms_ += traced_ms;
  }
  volume_radius_ = volume_kernel_radius(maps_->volume.size());
  volume_count_ = static_cast<GLsizei>(maps_->volume.size());  // reported; no splat buffer
  volume_grid_ = std::make_unique<VolumeGridResources>(
      bin_volume_photons(maps_->volume, scene_.medium_field(), volume_radius_, scene_box(scene_)));
  photon_upload_ms_ +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() -
      traced_ms;
}

void SceneResources::upload_direct() {
  Aabb box;
  std::vector<std::vector<DirectPoint>> per_light;
  for (const Light& l : scene_.lights) {
    per_light.push_back(std::visit(
        [&](const auto& kind) { return kind.direct_points(scene_.gi.direct_samples); }, l.shape));
  }
  // Interleaved lights' points first (direct_interleaved()), then the others.
  for (const bool first : {true, false}) {
    for (std::size_t k = 0; k < per_light.size(); ++k) {
      const std::vector<DirectPoint>& points = per_light[k];
      if (interleaves_direct_points(scene_.gi, points.size()) != first) continue;
      for (const DirectPoint& p : points) {
        box.grow(p.position);
        direct_points_.push_back(p);
        direct_flux_.push_back(scene_.lights[k].flux);
      }
      if (first) direct_interleaved_ += static_cast<int>(points.size());
    }
  }
  direct_anchor_ = box.empty() ? Vec3{0.0, 0.0, 0.0} : box.centre();
  // std430 record of shaders/direct_light.frag.
  struct PointData {
    float position[4];  // xyz: relative to direct_anchor(); w: DirectPoint::Mode
    float axis[4];      // xyz: unit axis; w: cos_outer
    float flux[4];      // rgb: the light's flux x scale; w: cos_inner
  };
  std::vector<PointData> data;
  for (std::size_t i = 0; i < direct_points_.size(); ++i) {
    const DirectPoint& p = direct_points_[i];
    PointData d{};
    for (std::size_t k = 0; k < 3; ++k) {
      d.position[k] = static_cast<float>(p.position[k] - direct_anchor_[k]);
      d.axis[k] = static_cast<float>(p.axis[k]);
      d.flux[k] = static_cast<float>(direct_flux_[i][k] * p.scale);
    }
    d.position[3] = static_cast<float>(static_cast<int>(p.mode));
    d.axis[3] = static_cast<float>(p.cos_outer);
    d.flux[3] = static_cast<float>(p.cos_inner);
    data.push_back(d);
  }
  if (!data.empty()) {
    GLuint id = 0;
    glCreateBuffers(1, &id);
    direct_ssbo_ = GlBuffer(id);
    glNamedBufferStorage(id, static_cast<GLsizeiptr>(data.size() * sizeof(PointData)), data.data(),
                         0);
  }
  // The interleave orders the points, and each point has its shadow map.
  shadow_key_ = photon_key(scene_) + "|" + std::to_string(scene_.gi.direct_samples) + "|" +
                std::to_string(scene_.gi.shadow_size) + "|" +
                std::to_string(scene_.gi.direct_interleave);
  gl_check("upload direct points");
}

// Lit scenes: the seen lights (those with an outline) are drawn as what a
// camera sees of them, their radiance from the front (G-buffer material code
// kEmitterMaterial).
struct SeenEmitter {
  const Light* light;
  LightOutline outline;
  Color radiance;
};
static std::vector<SeenEmitter> emitters_of(const Scene& scene) {
  std::vector<SeenEmitter> out;
  if (!scene.has_gi()) return out;
  for (const Light& l : scene.lights) {
    std::visit(
        [&](const auto& kind) {
          if (const std::optional<LightOutline> o = kind.outline()) {
            out.push_back({&l, *o, kind.radiance_scale() * l.flux});
          }
        },
        l.shape);
  }
  return out;
}

std::string SceneResources::occluder_key(const Scene& scene) {
  // Exact values, except a mesh's vertices and triangles, named by their
  // hashes (mesh_content_key).
  std::string key = "occluders";
  for (const Occluder& occ : scene.occluders) {
    std::visit(
        [&](const auto& shape) {
          using Kind = std::decay_t<decltype(shape)>;
          if constexpr (Kind::kGpu == GpuForm::kTriangles) {
            key.push_back('|');
            key.append(Kind::kType);
            append_raw(&key, occ.albedo);
            key.push_back(static_cast<char>('0' + static_cast<int>(occ.material.type)));
            if constexpr (std::is_same_v<Kind, MeshOccluder>) {
              key += shape.content_key.empty() ? mesh_content_key(shape) : shape.content_key;
            } else {
              KeySink sink(&key);
              shape.gpu_triangles(sink);
            }
          }
        },
        occ.shape);
  }
  for (const SeenEmitter& e : emitters_of(scene)) {
    key += "|emitter";
    LightKey k;
    std::visit([&](const auto& kind) { kind.cache_key(k); }, e.light->shape);
    key += std::to_string(e.light->shape.index()) + ":" + std::to_string(k.bytes.size()) + ":";
    key += k.bytes;
    append_raw(&key, e.radiance);
  }
  return key;
}

void SceneResources::upload_occluders(SceneGpuCache* content) {
  const Scene& scene = scene_;
  // Triangle kinds go into one vertex buffer, stored relative to an anchor
  // (the centre of their bounds) so float precision follows the geometry;
  // analytic kinds are ray-traced from a per-camera record (fill_analytic).
  Aabb bounds;
  for (const Occluder& occ : scene.occluders) {
    std::visit(
        [&](const auto& shape) {
          using Kind = std::decay_t<decltype(shape)>;
          if constexpr (Kind::kGpu == GpuForm::kTriangles) {
            bounds.grow(shape.bounds());
          } else if constexpr (Kind::kGpu == GpuForm::kAnalytic) {
            analytic_.push_back(&occ);
          }  // kPoints: the slim pass's own data
        },
        occ.shape);
  }
  for (const SeenEmitter& e : emitters_of(scene)) {
    bounds.grow(std::visit([](const auto& kind) { return kind.bounds(); }, e.light->shape));
  }
  mesh_bounds_ = bounds;
  if (!bounds.empty()) {
    mesh_anchor_ = bounds.centre();
    // The triangles depend only on the scene's content: kept across renders.
    const std::string key = content ? occluder_key(scene) : std::string();
    if (content) geometry_ = content->find<OccluderGeometry>(key);
    if (!geometry_) {
      geometry_ = make_geometry();
      if (content && geometry_) {
        content->put(key, geometry_,
                     static_cast<std::size_t>(geometry_->vertices) * sizeof(Vertex) + key.size());
      }
    }
  }
  if (!analytic_.empty()) {
    GLuint id = 0;
    glCreateBuffers(1, &id);
    analytic_ssbo_ = GlBuffer(id);
    glNamedBufferStorage(id, static_cast<GLsizeiptr>(sizeof(AnalyticData) * analytic_.size()),
                         nullptr, GL_DYNAMIC_STORAGE_BIT);
  }
}

// The vertex buffer of the triangle occluders and emitters, relative to
// mesh_anchor_; null without a triangle.
std::shared_ptr<const OccluderGeometry> SceneResources::make_geometry() const {
  std::vector<Vertex> verts;
  VertexSink sink(mesh_anchor_, &verts);
  for (const Occluder& occ : scene_.occluders) {
    sink.albedo = occ.albedo;
    sink.material = static_cast<float>(occ.material.type);
    std::visit(
        [&](const auto& shape) {
          if constexpr (std::decay_t<decltype(shape)>::kGpu == GpuForm::kTriangles) {
            shape.gpu_triangles(sink);
          }
        },
        occ.shape);
  }
  sink.material = kEmitterMaterial;
  for (const SeenEmitter& e : emitters_of(scene_)) {
    sink.albedo = e.radiance;  // the surface shader writes it as emitted radiance
    std::visit([&](const auto& kind) { kind.outline_triangles(sink); }, e.light->shape);
  }
  if (verts.empty()) return nullptr;
  auto g = std::make_shared<OccluderGeometry>();
  GLuint id = 0;
  glCreateBuffers(1, &id);
  g->vbo = GlBuffer(id);
  glNamedBufferStorage(id, static_cast<GLsizeiptr>(verts.size() * sizeof(Vertex)), verts.data(),
                       0);
  glCreateVertexArrays(1, &id);
  g->vao = GlVertexArray(id);
  glVertexArrayVertexBuffer(id, 0, g->vbo.get(), 0, sizeof(Vertex));
  // position, normal, albedo (3 floats each), one_sided, material (1 float each).
  for (GLuint a = 0; a < 5; ++a) {
    glEnableVertexArrayAttrib(id, a);
    glVertexArrayAttribFormat(id, a, a < 3 ? 3 : 1, GL_FLOAT, GL_FALSE,
                              static_cast<GLuint>((a < 4 ? a * 3 : 10) * sizeof(float)));
    glVertexArrayAttribBinding(id, a, 0);
  }
  g->vertices = static_cast<GLsizei>(verts.size());
  g->anchor = mesh_anchor_;
  g->bounds = mesh_bounds_;
  gl_check("upload occluder triangles");
  return g;
}

void SceneResources::fill_camera(const Camera& cam, const CameraBasis& basis, void* block) const {
  const Vec3& eye = basis.eye;
  CameraBlock& cb = *static_cast<CameraBlock*>(block);
  cb = CameraBlock{};
  view_projection(cam, basis, cb.view_proj);
  const bool ortho = cam.projection == Projection::kOrthographic;
  set3(cb.right, basis.right,
       static_cast<float>(ortho ? basis.half_height : basis.tan_half_fov));
  set3(cb.up, basis.up, static_cast<float>(basis.aspect));
  set3(cb.forward, basis.forward, ortho ? 1.0f : 0.0f);
  cb.viewport[0] = static_cast<float>(cam.width);
  cb.viewport[1] = static_cast<float>(cam.height);
  cb.viewport[2] = static_cast<float>(cam.near_plane);
  cb.viewport[3] = static_cast<float>(cam.far_plane);
  const DirectionalLight& light = scene_.light;
  set3(cb.light_dir, normalize(-1.0 * light.direction), static_cast<float>(light.ambient));
  set3(cb.light_color, light.color, static_cast<float>(light.intensity));
  set3(cb.mesh_offset, mesh_anchor_ - eye, 0.0f);
}

bool beam_proxy_full_screen(const BeamGpu& g, double radius, const Camera& cam,
                            const CameraBasis& basis) {
  if (cam.projection != Projection::kPerspective) return false;
  // Half the diagonal of the near plane's rectangle: the farthest a clipped
  // proxy's visible part can start from the eye.
  const double tan_y = basis.tan_half_fov;
  const double tan_x = tan_y * basis.aspect;
  const double near_corner = cam.near_plane * std::sqrt(1.0 + tan_x * tan_x + tan_y * tan_y);
  // Twice that, and a float-rounding share of the box, keep the rasterized
  // box well away from the cases it cannot cover.
  return proxy_box_distance(g, radius) <= 2.0 * near_corner + 1e-5 * radius;
}

void SceneResources::fill_beams(const Camera& cam, const CameraBasis& basis, void* beams) const {
  const Vec3& eye = basis.eye;
  auto* data = static_cast<BeamData*>(beams);
  for (std::size_t i = 0; i < beam_layers_.size(); ++i) {
    const Beam& beam = scene_.beams[i];
    BeamData& d = data[i];
    d = BeamData{};
    const auto r = static_cast<float>(beam.radius);
    const Color c = (beam.intensity) * beam.color;
    set3(d.color_layer, c, beam_layers_[i]);
    d.density[0] = static_cast<float>(static_cast<int>(beam.density.kind));
    d.density[1] = static_cast<float>(beam.density.sigma);
    const BeamGpu g = std::visit([&](const auto& shape) { return shape.gpu(eye); }, beam.shape);
    set3(d.p0_radius, g.p0, r);
    set3(d.axis_length, g.axis, static_cast<float>(g.length));
    set3(d.caps_kind, g.caps_kind, 0.0f);
    d.density[2] = beam_proxy_full_screen(g, beam.radius, cam, basis) ? 1.0f : 0.0f;
  }
}

void SceneResources::fill_analytic(const Vec3& eye, void* analytic) const {
  auto* data = static_cast<AnalyticData*>(analytic);
  for (std::size_t i = 0; i < analytic_.size(); ++i) {
    const Occluder& occ = *analytic_[i];
    AnalyticData& d = data[i];
    d = AnalyticData{};
    set3(d.albedo, occ.albedo, static_cast<float>(occ.material.type));
    const AnalyticGpu g = std::visit(
        [&](const auto& shape) {
          if constexpr (std::decay_t<decltype(shape)>::kGpu == GpuForm::kAnalytic) {
            return shape.analytic(eye);
          } else {
            return AnalyticGpu{};  // not in analytic_
          }
        },
        occ.shape);
    for (int k = 0; k < 4; ++k) {
      d.a[k] = static_cast<float>(g.a[k]);
      d.b[k] = static_cast<float>(g.b[k]);
    }
  }
}

void SceneResources::bind_camera(const Camera& cam, const CameraBasis& basis) {
  views_ = false;
  CameraBlock cb;
  fill_camera(cam, basis, &cb);
  glNamedBufferSubData(camera_ubo_.get(), 0, sizeof cb, &cb);
  if (beam_ssbo_) {
    std::vector<BeamData> data(beam_layers_.size());
    fill_beams(cam, basis, data.data());
    glNamedBufferSubData(beam_ssbo_.get(), 0,
                         static_cast<GLsizeiptr>(data.size() * sizeof(BeamData)), data.data());
  }
  if (analytic_ssbo_) {
    std::vector<AnalyticData> data(analytic_.size());
    fill_analytic(basis.eye, data.data());
    glNamedBufferSubData(analytic_ssbo_.get(), 0,
                         static_cast<GLsizeiptr>(data.size() * sizeof(AnalyticData)),
                         data.data());
  }
  gl_check("bind_camera");
}

void SceneResources::bind_views(const std::vector<Camera>& cams,
                                const std::vector<CameraBasis>& bases, int max_views) {
  const std::size_t k = cams.size();
  const std::size_t nb = beam_layers_.size(), na = analytic_.size();
  if (k > views_capacity_) {
    // Sized for the largest batch seen; a buffer of zero bytes is not allowed.
    auto make = [](GlBuffer& buf, std::size_t bytes) {
      GLuint id = 0;
      glCreateBuffers(1, &id);
      buf = GlBuffer(id);
      glNamedBufferStorage(id, static_cast<GLsizeiptr>(std::max<std::size_t>(bytes, 16)), nullptr,
                           GL_DYNAMIC_STORAGE_BIT);
    };
    // The shaders declare a fixed array of max_views blocks: the buffer backs all of it.
    make(views_camera_ubo_, static_cast<std::size_t>(max_views) * sizeof(CameraBlock));
    make(views_beam_ssbo_, k * nb * sizeof(BeamData));
    make(views_analytic_ssbo_, k * na * sizeof(AnalyticData));
    views_capacity_ = k;
  }
  std::vector<CameraBlock> blocks(k);
  std::vector<BeamData> beams(k * nb);
  std::vector<AnalyticData> analytic(k * na);
  for (std::size_t v = 0; v < k; ++v) {
    fill_camera(cams[v], bases[v], &blocks[v]);
    fill_beams(cams[v], bases[v], beams.data() + v * nb);
    fill_analytic(bases[v].eye, analytic.data() + v * na);
  }
  glNamedBufferSubData(views_camera_ubo_.get(), 0,
                       static_cast<GLsizeiptr>(blocks.size() * sizeof(CameraBlock)),
                       blocks.data());
  if (nb > 0) {
    glNamedBufferSubData(views_beam_ssbo_.get(), 0,
                         static_cast<GLsizeiptr>(beams.size() * sizeof(BeamData)), beams.data());
  }
  if (na > 0) {
    glNamedBufferSubData(views_analytic_ssbo_.get(), 0,
                         static_cast<GLsizeiptr>(analytic.size() * sizeof(AnalyticData)),
                         analytic.data());
  }
  views_ = true;
  gl_check("bind_views");
}

}  // namespace beamcast
