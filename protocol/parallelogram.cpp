#include "protocol/parallelogram.hpp"

#include "protocol/scene_readers.hpp"

#include <utility>

namespace beamcast {

using namespace json_read;

Parallelogram Parallelogram::read(const ObjectReader& fields, const SceneLimits& limits,
                                  const char* what) {
  Parallelogram q;
  q.corner = read_point(fields.required("corner"), limits);
  const Node u = fields.required("edge_u");
  q.edge_u = read_point(u, limits);
  const Node v = fields.required("edge_v");
  q.edge_v = read_point(v, limits);
  for (const auto& [node, edge] : {std::pair{&u, q.edge_u}, std::pair{&v, q.edge_v}}) {
    if (!(length(edge) >= kMinLength)) {
      fail("invalid_value", node->path,
           node->name() + " must be at least " + format_number(kMinLength) + " long (the " +
               what + "'s edge), got length " + format_number(length(edge)));
    }
  }
  // Scale-free: the sine of the angle between the unit edges (1e-9 * |u| *
  // |v| underflowed for tiny edges: issue 43).
  if (!(length(cross(normalize(q.edge_u), normalize(q.edge_v))) > 1e-9)) {
    fail("invalid_value", v.path,
         std::string("edge_v must not be parallel to edge_u (the ") + what +
             " would have no area)");
  }
  // Its area's square (hit()'s n . n) and the GPU's float cross product stay normal numbers.
  const double area = q.area();
  if (!(area >= kMinLength * kMinLength)) {
    fail("invalid_value", v.path,
         std::string("the ") + what + "'s area |edge_u x edge_v| must be at least " +
             format_number(kMinLength * kMinLength) + ", got " + format_number(area));
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
