#include "protocol/parallelogram.hpp"

#include "protocol/scene_readers.hpp"

namespace beamcast {

using namespace json_read;

Parallelogram Parallelogram::read(const ObjectReader& fields, const SceneLimits& limits,
                                  const char* what) {
  Parallelogram q;
  q.corner = read_point(fields.required("corner"), limits);
  q.edge_u = read_point(fields.required("edge_u"), limits);
  const Node v = fields.required("edge_v");
  q.edge_v = read_point(v, limits);
  const double area = length(q.normal_unnormalized());
  if (!(area > 1e-9 * length(q.edge_u) * length(q.edge_v))) {
    fail("invalid_value", v.path,
         std::string("edge_v must not be zero or parallel to edge_u (the ") + what +
             " would have no area)");
  }
  return q;
}

Aabb Parallelogram::bounds() const {
  Aabb b;
  for (const Vec3& p : {corner, corner + edge_u, corner + edge_v, corner + edge_u + edge_v}) {
    b.grow(p);
  }
  return b;
}

std::optional<double> Parallelogram::hit(const Vec3& o, const Vec3& v, double t_min, double t_max,
                                         bool front_only) const {
  const Vec3 n = normal_unnormalized();
  const double denom = dot(v, n);
  if (denom == 0.0 || (front_only && denom > 0.0)) return std::nullopt;
  const double t = dot(corner - o, n) / denom;
  if (!(t >= t_min && t <= t_max)) return std::nullopt;
  // The hit point's coordinates along the edges: p = a edge_u + b edge_v.
  const Vec3 p = (o + t * v) - corner;
  const double n2 = dot(n, n);
  const double a = dot(cross(p, edge_v), n) / n2;
  const double b = dot(cross(edge_u, p), n) / n2;
  if (a < 0.0 || a > 1.0 || b < 0.0 || b > 1.0) return std::nullopt;
  return t;
}

}  // namespace beamcast
