#include "protocol/occluders/sphere.hpp"

#include <cmath>

#include "protocol/occluders/occluder_parse.hpp"

namespace beamcast {

SphereOccluder SphereOccluder::parse(const OccluderParse& in) {
  in.allow({"center", "radius"});
  SphereOccluder s;
  s.center = json_read::read_point(in.fields.required("center"), in.limits());
  s.radius = json_read::read_size(in.fields.required("radius"), in.limits());
  return s;
}

Aabb SphereOccluder::bounds() const {
  const Vec3 r{radius, radius, radius};
  return Aabb{center - r, center + r};
}

AnalyticGpu SphereOccluder::analytic(const Vec3& eye) const {
  const Vec3 c = center - eye;
  return {{c[0], c[1], c[2], radius}, {0.0, 0.0, 0.0, 1.0}};
}

std::optional<OccluderHit> SphereOccluder::intersect(const Vec3& o, const Vec3& v, double t_min,
                                                     double t_max) const {
  const Vec3 e = center - o;
  const double tc = dot(e, v);
  const Vec3 perp = e - tc * v;
  const double d = length(perp);
  if (!(d <= radius)) return std::nullopt;
  const double h = std::sqrt((radius - d) * (radius + d));
  double t = tc - h;
  if (!(t >= t_min && t <= t_max)) t = tc + h;
  if (!(t >= t_min && t <= t_max)) return std::nullopt;
  return OccluderHit{t, (1.0 / radius) * ((o + t * v) - center)};
}

}  // namespace beamcast
