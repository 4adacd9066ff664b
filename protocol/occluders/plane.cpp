#include "protocol/occluders/plane.hpp"

#include "protocol/occluders/occluder_parse.hpp"

namespace beamcast {

PlaneOccluder PlaneOccluder::parse(const OccluderParse& in) {
  in.allow({"point", "normal"});
  PlaneOccluder p;
  p.point = json_read::read_point(in.fields.required("point"), in.limits());
  p.normal = json_read::read_direction(in.fields.required("normal"));
  return p;
}

Aabb PlaneOccluder::bounds() const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  return Aabb{{-kInf, -kInf, -kInf}, {kInf, kInf, kInf}};
}

AnalyticGpu PlaneOccluder::analytic(const Vec3& eye) const {
  // The plane's point nearest the eye, computed in double, keeps the plane
  // exact near the camera whatever point the scene gave.
  const Vec3 n = normalize(normal);
  const Vec3 nearest = dot(point - eye, n) * n;
  return {{nearest[0], nearest[1], nearest[2], 0.0}, {n[0], n[1], n[2], 0.0}};
}

std::optional<OccluderHit> PlaneOccluder::intersect(const Vec3& o, const Vec3& v, double t_min,
                                                    double t_max) const {
  const Vec3 n = normalize(normal);
  const double denom = dot(v, n);
  if (denom == 0.0) return std::nullopt;
  const double t = dot(point - o, n) / denom;
  if (t >= t_min && t <= t_max) return OccluderHit{t, n};
  return std::nullopt;
}

}  // namespace beamcast
