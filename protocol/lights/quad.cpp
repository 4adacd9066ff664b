#include "protocol/lights/quad.hpp"

#include <numbers>

#include "protocol/lights/light_parse.hpp"
#include "protocol/lights/sampling.hpp"

namespace beamcast {

using namespace json_read;

QuadLight QuadLight::parse(const LightParse& in) {
  QuadLight q;
  q.corner = read_point(in.fields.required("corner"), in.limits);
  q.edge_u = read_point(in.fields.required("edge_u"), in.limits);
  const Node v = in.fields.required("edge_v");
  q.edge_v = read_point(v, in.limits);
  const Vec3 n = cross(q.edge_u, q.edge_v);
  q.area = length(n);
  // The rule of the quad occluder: sin(angle between the edges) >= 1e-9.
  if (!(q.area > 1e-9 * length(q.edge_u) * length(q.edge_v))) {
    fail("invalid_value", v.path,
         "edge_v must not be zero or parallel to edge_u (the light would have no area)");
  }
  q.normal = (1.0 / q.area) * n;
  return q;
}

Aabb QuadLight::bounds() const {
  Aabb b;
  for (const Vec3& p : {corner, corner + edge_u, corner + edge_v, corner + edge_u + edge_v}) {
    b.grow(p);
  }
  return b;
}

Emission QuadLight::emit(const LightRandom& u) const {
  // Uniform in area, cosine-weighted in direction: each photon carries an
  // equal share of a Lambertian emitter's flux.
  return {corner + u[0] * edge_u + u[1] * edge_v, cosine_hemisphere(normal, u[2], u[3]), 1.0};
}

LightSample QuadLight::sample(const Vec3& x, const LightRandom& u) const {
  const Vec3 y = corner + u[0] * edge_u + u[1] * edge_v;
  const Vec3 d = y - x;
  const double dist = length(d);
  if (!(dist > 0.0)) return {};
  const Vec3 dir = (1.0 / dist) * d;
  const double cos_y = -dot(dir, normal);
  if (cos_y <= 0.0) return {y, dir, dist, 0.0};
  // Radiance per unit flux 1 / (pi A), times cos_y / d^2, over the area pdf 1 / A.
  return {y, dir, dist, cos_y / (std::numbers::pi * dist * dist)};
}

std::optional<double> QuadLight::hit(const Vec3& o, const Vec3& v, double t_max) const {
  const double denom = dot(v, normal);
  if (denom >= 0.0) return std::nullopt;  // seen only from the side it emits to
  const double t = dot(corner - o, normal) / denom;
  if (!(t > 0.0 && t <= t_max)) return std::nullopt;
  const Vec3 p = (o + t * v) - corner;
  const Vec3 n = cross(edge_u, edge_v);
  const double n2 = dot(n, n);
  const double a = dot(cross(p, edge_v), n) / n2;
  const double b = dot(cross(edge_u, p), n) / n2;
  if (a < 0.0 || a > 1.0 || b < 0.0 || b > 1.0) return std::nullopt;
  return t;
}

double QuadLight::radiance_scale() const { return 1.0 / (std::numbers::pi * area); }

}  // namespace beamcast
