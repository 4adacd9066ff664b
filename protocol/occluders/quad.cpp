#include "protocol/occluders/quad.hpp"

#include <cmath>

#include "protocol/occluders/occluder_parse.hpp"
#include "protocol/parallelogram.hpp"

namespace beamcast {

using namespace json_read;

QuadOccluder QuadOccluder::parse(const OccluderParse& in) {
  in.allow({"corner", "edge_u", "edge_v", "sides"});
  QuadOccluder q;
  const Parallelogram p = Parallelogram::read(in.fields, in.limits(), "quad");
  q.corner = p.corner;
  q.edge_u = p.edge_u;
  q.edge_v = p.edge_v;
  if (auto s = in.fields.optional("sides")) {
    const std::int64_t sides = read_integer(*s);
    if (sides != 1 && sides != 2) {
      fail("invalid_value", s->path,
           "sides must be 1 (seen from the side of cross(edge_u, edge_v)) or 2, got " +
               std::to_string(sides));
    }
    q.two_sided = sides == 2;
  }
  return q;
}

Aabb QuadOccluder::bounds() const { return Parallelogram{corner, edge_u, edge_v}.bounds(); }

void QuadOccluder::gpu_triangles(TriangleSink& out) const {
  // Both triangles' normals point along cross(edge_u, edge_v).
  const Vec3 far = corner + edge_u + edge_v;
  out.add(corner, corner + edge_u, far, !two_sided);
  out.add(corner, far, corner + edge_v, !two_sided);
}

std::optional<OccluderHit> QuadOccluder::intersect(const Vec3& o, const Vec3& v, double t_min,
                                                   double t_max) const {
  // A one-sided quad is hit only by rays against its normal.
  const auto t = Parallelogram{corner, edge_u, edge_v}.hit(o, v, t_min, t_max, !two_sided);
  if (!t) return std::nullopt;
  return OccluderHit{*t, normalize(cross(edge_u, edge_v))};
}

}  // namespace beamcast
