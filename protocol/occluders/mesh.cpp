#include "protocol/occluders/mesh.hpp"

#include <cmath>
#include <functional>
#include <string_view>

#include "protocol/mesh_obj.hpp"
#include "protocol/occluders/occluder_parse.hpp"

namespace beamcast {

using namespace json_read;

MeshOccluder MeshOccluder::parse(const OccluderParse& in) {
  in.allow({"file", "translate", "scale", "rotation"});
  const Node file = in.fields.required("file");
  const std::string name = read_string(file);
  if (name.empty()) fail("invalid_value", file.path, "file must be a non-empty relative path");
  const MeshTransform xf = parse_mesh_transform(in.fields, in.limits());
  const MeshLoadLimits mesh_limits{in.limits().max_mesh_triangles, *in.mesh_triangles,
                                   in.limits().max_abs_coordinate};
  MeshOccluder mesh = load_obj_mesh(in.opts.assets_dir, name, xf, mesh_limits, file.path);
  *in.mesh_triangles += static_cast<std::int64_t>(mesh.triangles.size());
  mesh.box = mesh.bounds();
  mesh.content_key = mesh_content_key(mesh);
  return mesh;
}

std::string mesh_content_key(const MeshOccluder& mesh) {
  const std::string_view v(reinterpret_cast<const char*>(mesh.vertices.data()),
                           mesh.vertices.size() * sizeof(Vec3));
  const std::string_view t(reinterpret_cast<const char*>(mesh.triangles.data()),
                           mesh.triangles.size() * sizeof(mesh.triangles[0]));
  const std::size_t hv = std::hash<std::string_view>{}(v);
  const std::size_t ht = std::hash<std::string_view>{}(t);
  return "mesh:" + std::to_string(mesh.vertices.size()) + ":" + std::to_string(hv) + ":" +
         std::to_string(mesh.triangles.size()) + ":" + std::to_string(ht);
}

Aabb MeshOccluder::bounds() const {
  if (!box.empty()) return box;  // set by parse
  Aabb b;
  for (const Vec3& v : vertices) b.grow(v);
  return b;
}

void MeshOccluder::gpu_triangles(TriangleSink& out) const {
  for (const auto& tri : triangles) {
    out.add(vertices[tri[0]], vertices[tri[1]], vertices[tri[2]], false);
  }
}

std::optional<OccluderHit> MeshOccluder::intersect(const Vec3& o, const Vec3& v, double t_min,
                                                   double t_max) const {
  if (vertices.empty() || triangles.empty()) return std::nullopt;
  if (!box.empty()) {
    double tn, tf;
    int an, af;
    if (!ray_box(o, v, box, &tn, &tf, &an, &af)) return std::nullopt;
    if (tf < t_min || tn > t_max) return std::nullopt;
  }
  std::optional<OccluderHit> best;
  const std::size_t nv = vertices.size();
  for (const auto& tri : triangles) {
    if (tri[0] >= nv || tri[1] >= nv || tri[2] >= nv) continue;
    // Moller-Trumbore.
    const Vec3& p0 = vertices[tri[0]];
    const Vec3 e1 = vertices[tri[1]] - p0;
    const Vec3 e2 = vertices[tri[2]] - p0;
    const Vec3 pv = cross(v, e2);
    const double det = dot(e1, pv);
    if (det == 0.0) continue;
    const double inv = 1.0 / det;
    const Vec3 tv = o - p0;
    const double bu = dot(tv, pv) * inv;
    if (bu < 0.0 || bu > 1.0) continue;
    const Vec3 qv = cross(tv, e1);
    const double bv = dot(v, qv) * inv;
    if (bv < 0.0 || bu + bv > 1.0) continue;
    const double t = dot(e2, qv) * inv;
    if (t >= t_min && t <= t_max) {
      t_max = t;
      best = OccluderHit{t, normalize(cross(e1, e2))};
    }
  }
  return best;
}

}  // namespace beamcast
