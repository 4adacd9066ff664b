#include "render/specular_gpu.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <string>
#include <variant>

#include "protocol/occluders/occluders.hpp"

namespace beamcast {

bool gpu_traces_specular(const Scene& scene) {
  if (scene.has_medium()) return false;
  return std::none_of(scene.occluders.begin(), scene.occluders.end(), [](const Occluder& o) {
    return std::holds_alternative<SlimOccluder>(o.shape);
  });
}

namespace {

using Vec4f = std::array<float, 4>;

Vec4f v4(const Vec3& v, double w) {
  return {static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]),
          static_cast<float>(w)};
}

// Material types of shaders/specular_trace.comp: MaterialType's codes, and
// 3 for a seen light (albedo.rgb its radiance).
constexpr double kLightMaterial = 3.0;

struct MaterialRecord {
  Vec4f albedo;    // rgb; w: type
  Vec4f specular;  // rgb: mirror reflectance or glass tint; w: ior
};

struct ShapeRecord {
  Vec4f a, b, c, d;  // see specular_trace.comp's Shape
};

struct TriangleRecord {
  Vec4f a;   // xyz: corner (anchor-relative); w: material
  Vec4f e1;  // xyz: b - a; w: 1 one-sided
  Vec4f e2;  // xyz: c - a
  Vec4f n;   // xyz: unit normal cross(e1, e2), from double
};

struct PhotonRecord {
  Vec4f p;      // xyz: position (anchor-relative); w: cell x
  Vec4f n;      // xyz: unit normal; w: cell y
  Vec4f power;  // rgb; w: cell z
};

struct DirectRecord {
  Vec4f p;     // xyz: position (anchor-relative); w: mode
  Vec4f axis;  // xyz; w: scale
  Vec4f flux;  // rgb; w: cos_inner
  Vec4f cone;  // x: cos_outer
};

class CollectTriangles final : public TriangleSink {
 public:
  CollectTriangles(const Vec3& anchor, int material, std::vector<TriangleRecord>* out)
      : anchor_(anchor), material_(material), out_(out) {}
  void add(const Vec3& a, const Vec3& b, const Vec3& c, bool one_sided) override {
    const Vec3 cr = cross(b - a, c - a);
    const double len = length(cr);
    if (!(len > 0.0)) return;  // no area: nothing to hit
    out_->push_back({v4(a - anchor_, material_), v4(b - a, one_sided ? 1.0 : 0.0), v4(c - a, 0.0),
                     v4((1.0 / len) * cr, 0.0)});
  }

 private:
  Vec3 anchor_;
  int material_;
  std::vector<TriangleRecord>* out_;
};

// The triangle's corners in float (as the shader rebuilds them).
std::array<std::array<float, 3>, 3> corners(const TriangleRecord& t) {
  std::array<std::array<float, 3>, 3> c{};
  for (int k = 0; k < 3; ++k) {
    c[0][k] = t.a[k];
    c[1][k] = t.a[k] + t.e1[k];
    c[2][k] = t.a[k] + t.e2[k];
  }
  return c;
}

// Median split on the longest axis of the centroids' bounds, leaves of at
// most 4 triangles; `tris` is reordered so that every leaf's are contiguous.
class BvhBuilder {
 public:
  BvhBuilder(std::vector<TriangleRecord>& tris, float pad) : tris_(tris), pad_(pad) {}
  std::vector<SpecularBvhNode> build() {
    if (tris_.empty()) return {};
    nodes_.push_back({});
    split(0, 0, static_cast<int>(tris_.size()));
    return std::move(nodes_);
  }

 private:
  static constexpr int kLeaf = 4;
  std::vector<TriangleRecord>& tris_;
  float pad_;
  std::vector<SpecularBvhNode> nodes_;

  static float centroid(const TriangleRecord& t, int axis) {
    return t.a[static_cast<std::size_t>(axis)] +
           (t.e1[static_cast<std::size_t>(axis)] + t.e2[static_cast<std::size_t>(axis)]) / 3.0f;
  }

  void split(std::size_t node, int first, int count) {
    SpecularBvhNode n{};
    std::array<float, 3> clo{}, chi{};
    for (int k = 0; k < 3; ++k) {
      n.lo[k] = clo[static_cast<std::size_t>(k)] = HUGE_VALF;
      n.hi[k] = chi[static_cast<std::size_t>(k)] = -HUGE_VALF;
    }
    for (int i = first; i < first + count; ++i) {
      const TriangleRecord& t = tris_[static_cast<std::size_t>(i)];
      for (const auto& p : corners(t)) {
        for (int k = 0; k < 3; ++k) {
          n.lo[k] = std::min(n.lo[k], p[static_cast<std::size_t>(k)]);
          n.hi[k] = std::max(n.hi[k], p[static_cast<std::size_t>(k)]);
        }
      }
      for (int k = 0; k < 3; ++k) {
        const float c = centroid(t, k);
        clo[static_cast<std::size_t>(k)] = std::min(clo[static_cast<std::size_t>(k)], c);
        chi[static_cast<std::size_t>(k)] = std::max(chi[static_cast<std::size_t>(k)], c);
      }
    }
    // Padded: the shader's float slab test must not miss a triangle it
    // would hit at the box's face.
    for (int k = 0; k < 3; ++k) {
      n.lo[k] -= pad_;
      n.hi[k] += pad_;
    }
    int axis = 0;
    for (int k = 1; k < 3; ++k) {
      if (chi[static_cast<std::size_t>(k)] - clo[static_cast<std::size_t>(k)] >
          chi[static_cast<std::size_t>(axis)] - clo[static_cast<std::size_t>(axis)])
        axis = k;
    }
    if (count <= kLeaf || !(chi[static_cast<std::size_t>(axis)] > clo[static_cast<std::size_t>(axis)])) {
      n.first = first;
      n.count = count;
      nodes_[node] = n;
      return;
    }
    const int half = count / 2;
    auto begin = tris_.begin() + first;
    std::nth_element(begin, begin + half, begin + count,
                     [axis](const TriangleRecord& x, const TriangleRecord& y) {
                       return centroid(x, axis) < centroid(y, axis);
                     });
    const std::size_t left = nodes_.size();
    nodes_.push_back({});
    nodes_.push_back({});
    n.first = static_cast<std::int32_t>(left);
    n.count = 0;
    nodes_[node] = n;
    split(left, first, half);
    split(left + 1, first + half, count - half);
  }
};

// The spatial hash of a cell (the shader's cell_hash): the same 32-bit
// wrap-around arithmetic on both sides.
std::uint32_t cell_hash(std::int32_t x, std::int32_t y, std::int32_t z) {
  return (static_cast<std::uint32_t>(x) * 73856093u) ^ (static_cast<std::uint32_t>(y) * 19349663u) ^
         (static_cast<std::uint32_t>(z) * 83492791u);
}

GlBuffer upload(const void* data, std::size_t bytes, GLint64 max_block, const char* what) {
  if (bytes > static_cast<std::uint64_t>(max_block)) {
    throw GlError(std::string("specular pass: the ") + what + " (" + std::to_string(bytes) +
                  " bytes) exceed the driver's largest shader storage block (" +
                  std::to_string(max_block) + ")");
  }
  GLuint id = 0;
  glCreateBuffers(1, &id);
  GlBuffer b(id);
  // A block is never bound to an empty buffer (GL refuses size 0).
  static const float kZero[16] = {};
  if (bytes == 0) {
    glNamedBufferStorage(id, sizeof(kZero), kZero, 0);
  } else {
    glNamedBufferStorage(id, static_cast<GLsizeiptr>(bytes), data, 0);
  }
  return b;
}

template <class T>
GlBuffer upload(const std::vector<T>& v, GLint64 max_block, const char* what) {
  return upload(v.data(), v.size() * sizeof(T), max_block, what);
}

}  // namespace

SpecularGpu::SpecularGpu(const Scene& scene, const PhotonMaps& maps, bool skip_direct) {
  // The anchor and the offset: the centre and the size of the bounds of
  // every bounded occluder and light (GiScene's extent).
  Aabb extent;
  for (const Occluder& o : scene.occluders) {
    const Aabb b = std::visit([](const auto& k) { return k.bounds(); }, o.shape);
    if (std::isfinite(b.lo[0]) && std::isfinite(b.hi[0])) extent.grow(b);
  }
  for (const Light& l : scene.lights) {
    extent.grow(std::visit([](const auto& k) { return k.bounds(); }, l.shape));
  }
  double size = 1.0;
  if (!extent.empty()) {
    anchor_ = extent.centre();
    const Vec3 d = extent.hi - extent.lo;
    size = std::max({d[0], d[1], d[2], 1.0});
  }
  // GiScene's offset is 1e-6 of the extent, in double. Float positions
  // within the extent are good to ~6e-8 of it, a hit's t to a few times
  // that: 1e-5 keeps a ray off the surface it leaves with two orders of
  // magnitude to spare.
  eps_ = static_cast<float>(1e-5 * size);
  for (int k = 0; k < 3; ++k) background_[k] = static_cast<float>(scene.background[static_cast<std::size_t>(k)]);
  kernel_ = scene.gi.kernel == SplatKernel::kBox ? 0 : scene.gi.kernel == SplatKernel::kCone ? 1 : 2;

  GLint64 max_block = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);

  std::vector<MaterialRecord> materials;
  std::vector<ShapeRecord> shapes;
  std::vector<TriangleRecord> tris;
  for (std::size_t i = 0; i < scene.occluders.size(); ++i) {
    const Occluder& o = scene.occluders[i];
    const Material& m = o.material;
    const Color& spec = m.type == MaterialType::kGlass ? m.tint : m.reflectance;
    materials.push_back({v4(o.albedo, static_cast<double>(static_cast<int>(m.type))), v4(spec, m.ior)});
    const int material = static_cast<int>(i);
    std::visit(
        [&](const auto& kind) {
          using Kind = std::decay_t<decltype(kind)>;
          if constexpr (std::is_same_v<Kind, SphereOccluder>) {
            shapes.push_back({v4(kind.center - anchor_, 1.0), v4(Vec3{0.0, 0.0, 0.0}, kind.radius),
                              v4(Vec3{0.0, 0.0, 0.0}, material), {}});
          } else if constexpr (std::is_same_v<Kind, PlaneOccluder>) {
            shapes.push_back({v4(kind.point - anchor_, 0.0), v4(normalize(kind.normal), 0.0),
                              v4(Vec3{0.0, 0.0, 0.0}, material), {}});
          } else if constexpr (Kind::kGpu == GpuForm::kTriangles) {
            CollectTriangles sink(anchor_, material, &tris);
            kind.gpu_triangles(sink);
          }
          // SLIM (kPoints): gpu_traces_specular keeps such scenes on the CPU.
        },
        o.shape);
  }
  for (std::size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    std::visit(
        [&](const auto& kind) {
          const std::optional<LightOutline> q = kind.outline();
          if (!q) return;  // never seen
          materials.push_back({v4(kind.radiance_scale() * l.flux, kLightMaterial), {}});
          shapes.push_back({v4(q->corner - anchor_, 2.0), v4(q->u, 0.0),
                            v4(q->v, static_cast<double>(materials.size() - 1)),
                            v4(cross(q->u, q->v), static_cast<double>(q->code))});
        },
        l.shape);
  }
  shape_count_ = static_cast<int>(shapes.size());
  std::vector<SpecularBvhNode> nodes = BvhBuilder(tris, 4.0f * eps_).build();
  node_count_ = static_cast<int>(nodes.size());

  // The photons, as PhotonGather keeps them, each map in its own grid.
  const SplatRadii radii = splat_radii(scene);
  std::vector<PhotonRecord> photons;
  std::vector<std::uint32_t> cells;
  const std::vector<Photon>* map_of[2] = {&maps.global, &maps.caustic};
  const double radius_of[2] = {radii.global, radii.caustic};
  for (int g = 0; g < 2; ++g) {
    std::vector<const Photon*> kept;
    Aabb box;
    for (const Photon& p : *map_of[g]) {
      if (skip_direct && p.bounces == 0) continue;
      kept.push_back(&p);
      box.grow(Vec3{p.p[0], p.p[1], p.p[2]} - anchor_);
    }
    Grid& grid = grids_[g];
    const double r = radius_of[g];
    if (kept.empty() || !(r > 0.0)) continue;
    // Cells a little over the radius, so a photon within r of a point lies
    // in its cell or a neighbour despite float rounding; at most 2^20 a
    // side, so cell coordinates stay exact in float.
    const Vec3 span = box.hi - box.lo;
    const double cell = std::max(1.001 * r, std::max({span[0], span[1], span[2]}) / 1048576.0);
    for (int k = 0; k < 3; ++k) grid.origin[k] = static_cast<float>(box.lo[static_cast<std::size_t>(k)]);
    grid.inv_cell = static_cast<float>(1.0 / cell);
    grid.radius = static_cast<float>(r);
    std::uint32_t table = 1;
    while (table < kept.size()) table <<= 1;
    grid.mask = static_cast<std::int32_t>(table - 1);
    grid.base = static_cast<std::int32_t>(cells.size());
    // Counting sort by bucket: bucket h's photons are
    // [cells[base + h], cells[base + h + 1]).
    std::vector<std::uint32_t> bucket(kept.size());
    std::vector<std::array<float, 3>> cell_of(kept.size());
    std::vector<std::uint32_t> count(table + 1, 0);
    for (std::size_t i = 0; i < kept.size(); ++i) {
      std::int32_t c[3];
      for (int k = 0; k < 3; ++k) {
        // In float, as the shader places its query points.
        const float rel = static_cast<float>(kept[i]->p[k] - anchor_[static_cast<std::size_t>(k)]);
        c[k] = static_cast<std::int32_t>(std::floor((rel - grid.origin[k]) * grid.inv_cell));
        cell_of[i][static_cast<std::size_t>(k)] = static_cast<float>(c[k]);
      }
      bucket[i] = cell_hash(c[0], c[1], c[2]) & static_cast<std::uint32_t>(grid.mask);
      ++count[bucket[i] + 1];
    }
    std::partial_sum(count.begin(), count.end(), count.begin());
    const auto first = static_cast<std::uint32_t>(photons.size());
    for (std::uint32_t& c : count) c += first;
    cells.insert(cells.end(), count.begin(), count.end());
    photons.resize(photons.size() + kept.size());
    std::vector<std::uint32_t> next(count.begin(), count.end() - 1);
    for (std::size_t i = 0; i < kept.size(); ++i) {
      const Photon& p = *kept[i];
      const Vec3 pos = Vec3{p.p[0], p.p[1], p.p[2]} - anchor_;
      photons[next[bucket[i]]++] = {v4(pos, cell_of[i][0]),
                                    v4(Vec3{p.n[0], p.n[1], p.n[2]}, cell_of[i][1]),
                                    v4(Vec3{p.power[0], p.power[1], p.power[2]}, cell_of[i][2])};
    }
  }

  // Direct light (LitShading's points) with gi.direct "shadow_maps".
  std::vector<DirectRecord> direct;
  if (scene.gi.direct == DirectLightMethod::kShadowMaps) {
    for (const Light& l : scene.lights) {
      const auto points = std::visit(
          [&](const auto& kind) { return kind.direct_points(scene.gi.direct_samples); }, l.shape);
      for (const DirectPoint& p : points) {
        direct.push_back({v4(p.position - anchor_, static_cast<double>(static_cast<int>(p.mode))),
                          v4(p.axis, p.scale), v4(l.flux, p.cos_inner),
                          {static_cast<float>(p.cos_outer), 0.0f, 0.0f, 0.0f}});
      }
    }
  }
  direct_count_ = static_cast<int>(direct.size());

  shapes_ = upload(shapes, max_block, "shapes");
  materials_ = upload(materials, max_block, "materials");
  nodes_ = upload(nodes, max_block, "BVH nodes");
  triangles_ = upload(tris, max_block, "triangles");
  photons_ = upload(photons, max_block, "photons");
  cells_ = upload(cells, max_block, "photon grid cells");
  direct_ = upload(direct, max_block, "direct light points");
  gl_check("upload specular tracing data");
}

void SpecularGpu::bind(GLuint program) const {
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kShapes, shapes_.get());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kMaterials, materials_.get());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kNodes, nodes_.get());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kTriangles, triangles_.get());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kPhotons, photons_.get());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kCells, cells_.get());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kDirect, direct_.get());
  auto loc = [&](const char* name) { return glGetUniformLocation(program, name); };
  glUniform1i(loc("u_shape_count"), shape_count_);
  glUniform1i(loc("u_node_count"), node_count_);
  glUniform1i(loc("u_direct_count"), direct_count_);
  glUniform1f(loc("u_eps"), eps_);
  glUniform3fv(loc("u_background"), 1, background_);
  glUniform1i(loc("u_kernel"), kernel_);
  for (int g = 0; g < 2; ++g) {
    const std::string i = "[" + std::to_string(g) + "]";
    glUniform3fv(loc(("u_grid_origin" + i).c_str()), 1, grids_[g].origin);
    glUniform1f(loc(("u_grid_inv_cell" + i).c_str()), grids_[g].inv_cell);
    glUniform1f(loc(("u_grid_radius" + i).c_str()), grids_[g].radius);
    glUniform1i(loc(("u_grid_base" + i).c_str()), grids_[g].base);
    glUniform1i(loc(("u_grid_mask" + i).c_str()), grids_[g].mask);
  }
}

}  // namespace beamcast
