#include "protocol/media/cylinder.hpp"

#include <algorithm>
#include <cmath>

#include "protocol/json_reader.hpp"
#include "protocol/scene_json.hpp"
#include "protocol/scene_readers.hpp"

namespace beamcast {

CylinderRegion CylinderRegion::parse(const RegionParse& in) {
  const SceneLimits& limits = in.opts.limits;
  CylinderRegion c;
  c.p0 = json_read::read_point(in.fields.required("p0"), limits);
  const json_read::Node p1 = in.fields.required("p1");
  c.p1 = json_read::read_point(p1, limits);
  c.radius = json_read::read_size(in.fields.required("radius"), limits);
  // The axis as the GPU sees it: its ends rounded to float.
  Vec3 axis{};
  for (std::size_t k = 0; k < 3; ++k) {
    axis[k] = static_cast<double>(static_cast<float>(c.p1[k])) -
              static_cast<double>(static_cast<float>(c.p0[k]));
  }
  const double len = length(c.p1 - c.p0);
  if (!(len >= json_read::kMinLength) || !(length(axis) > 0.0)) {
    json_read::fail("invalid_value", p1.path,
                    "p1 must differ from p0: a cylinder's axis needs a length (|p1 - p0| = " +
                        json_read::format_number(len) +
                        "; at least 1e-15 and apart in float, as the GPU holds the ends)");
  }
  return c;
}

Aabb CylinderRegion::bounds() const {
  // The caps' disks bound it: along axis k a disk of radius r perpendicular
  // to the unit axis u reaches r sqrt(1 - u_k^2).
  const Vec3 u = normalize(p1 - p0);
  Vec3 e{};
  for (std::size_t k = 0; k < 3; ++k) e[k] = radius * std::sqrt(std::max(0.0, 1.0 - u[k] * u[k]));
  Aabb box;
  box.grow(p0 - e);
  box.grow(p0 + e);
  box.grow(p1 - e);
  box.grow(p1 + e);
  return box;
}

bool CylinderRegion::contains(const Vec3& x) const {
  const Vec3 d = p1 - p0;
  const double len = length(d);
  const Vec3 u = (1.0 / len) * d;
  const Vec3 w = x - p0;
  const double s = dot(w, u);
  if (!(s >= 0.0 && s <= len)) return false;
  const Vec3 perp = w - s * u;
  return dot(perp, perp) <= radius * radius;
}

void CylinderRegion::clip(const Vec3& o, const Vec3& v, double* a, double* b) const {
  const Vec3 d = p1 - p0;
  const double len = length(d);
  const Vec3 u = (1.0 / len) * d;
  const Vec3 w = o - p0;
  // Between the caps: s(t) = wu + t vu in [0, len].
  const double wu = dot(w, u), vu = dot(v, u);
  if (vu == 0.0) {
    if (wu < 0.0 || wu > len) *b = *a;
  } else {
    const double ta = -wu / vu, tb = (len - wu) / vu;
    *a = std::max(*a, std::min(ta, tb));
    *b = std::min(*b, std::max(ta, tb));
  }
  // Within the radius of the axis line: |wp + t vp|^2 <= r^2, the parts
  // perpendicular to it, solved about the nearest approach tc (as a sphere's
  // chord).
  const Vec3 wp = w - wu * u, vp = v - vu * u;
  const double a2 = dot(vp, vp);
  if (!(a2 > 0.0)) {  // along the axis: inside the radius everywhere or nowhere
    if (dot(wp, wp) > radius * radius) *b = *a;
    return;
  }
  const double tc = -dot(wp, vp) / a2;
  const Vec3 q = wp + tc * vp;
  const double h2 = (radius * radius - dot(q, q)) / a2;
  if (!(h2 > 0.0)) {
    *b = *a;
    return;
  }
  const double h = std::sqrt(h2);
  *a = std::max(*a, tc - h);
  *b = std::min(*b, tc + h);
}

}  // namespace beamcast
