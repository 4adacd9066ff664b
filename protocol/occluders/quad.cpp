#include "protocol/occluders/quad.hpp"

#include <cmath>

#include "protocol/occluders/occluder_parse.hpp"

namespace beamcast {

using namespace json_read;

QuadOccluder QuadOccluder::parse(const OccluderParse& in) {
  in.allow({"corner", "edge_u", "edge_v", "sides"});
  QuadOccluder q;
  q.corner = read_point(in.fields.required("corner"), in.limits());
  q.edge_u = read_point(in.fields.required("edge_u"), in.limits());
  const Node v = in.fields.required("edge_v");
  q.edge_v = read_point(v, in.limits());
  // Parallel or zero edges leave no area (and no normal). The bound is
  // relative: sin(angle between the edges) below 1e-9 is refused, far from
  // any wall a scene means and far above double rounding (1e-16).
  const double area = length(cross(q.edge_u, q.edge_v));
  if (!(area > 1e-9 * length(q.edge_u) * length(q.edge_v))) {
    fail("invalid_value", v.path,
         "edge_v must not be zero or parallel to edge_u (the quad would have no area)");
  }
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

Aabb QuadOccluder::bounds() const {
  Aabb b;
  for (const Vec3& p : {corner, corner + edge_u, corner + edge_v, corner + edge_u + edge_v}) {
    b.grow(p);
  }
  return b;
}

void QuadOccluder::gpu_triangles(TriangleSink& out) const {
  // Both triangles' normals point along cross(edge_u, edge_v).
  const Vec3 far = corner + edge_u + edge_v;
  out.add(corner, corner + edge_u, far, !two_sided);
  out.add(corner, far, corner + edge_v, !two_sided);
}

std::optional<OccluderHit> QuadOccluder::intersect(const Vec3& o, const Vec3& v, double t_min,
                                                   double t_max) const {
  const Vec3 n = cross(edge_u, edge_v);
  const double denom = dot(v, n);
  // A one-sided quad is hit only by rays against its normal.
  if (denom == 0.0 || (!two_sided && denom > 0.0)) return std::nullopt;
  const double t = dot(corner - o, n) / denom;
  if (!(t >= t_min && t <= t_max)) return std::nullopt;
  // The hit point's coordinates along the edges: p = a edge_u + b edge_v.
  const Vec3 p = (o + t * v) - corner;
  const double n2 = dot(n, n);
  const double a = dot(cross(p, edge_v), n) / n2;
  const double b = dot(cross(edge_u, p), n) / n2;
  if (a < 0.0 || a > 1.0 || b < 0.0 || b > 1.0) return std::nullopt;
  return OccluderHit{t, normalize(n)};
}

}  // namespace beamcast
