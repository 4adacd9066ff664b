// Occluder "quad": the parallelogram corner + a edge_u + b edge_v, a and b in
// [0, 1], rasterized as two triangles. One-sided quads (sides 1) are seen and
// occlude only from the side cross(edge_u, edge_v) points to, so a box of
// inward-facing walls (a Cornell box) can be looked into from outside.
#pragma once

#include "protocol/occluders/occluder_base.hpp"

namespace beamcast {

struct QuadOccluder {
  static constexpr std::string_view kType = "quad";
  static constexpr GpuForm kGpu = GpuForm::kTriangles;
  Vec3 corner{};
  Vec3 edge_u{1.0, 0.0, 0.0};
  Vec3 edge_v{0.0, 0.0, 1.0};
  bool two_sided = true;

  static QuadOccluder parse(const OccluderParse& in);
  Aabb bounds() const;
  void gpu_triangles(TriangleSink& out) const;
  std::optional<OccluderHit> intersect(const Vec3& o, const Vec3& v, double t_min,
                                       double t_max) const;
};

}  // namespace beamcast
