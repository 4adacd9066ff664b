#include "protocol/media/sphere.hpp"

#include <algorithm>
#include <cmath>

#include "protocol/json_reader.hpp"
#include "protocol/scene_json.hpp"

namespace beamcast {

SphereRegion SphereRegion::parse(const RegionParse& in) {
  const double max_abs = in.opts.limits.max_abs_coordinate;
  SphereRegion r;
  const json_read::Node c = in.fields.required("center");
  r.center = json_read::check_coordinates(c, json_read::read_vec3(c), max_abs);
  const json_read::Node rad = in.fields.required("radius");
  r.radius = json_read::check_positive(rad, json_read::read_number(rad));
  if (r.radius > max_abs) {
    json_read::fail("out_of_range", rad.path,
                    "radius must be <= " + json_read::format_number(max_abs));
  }
  return r;
}

Aabb SphereRegion::bounds() const {
  const Vec3 r{radius, radius, radius};
  return Aabb{center - r, center + r};
}

bool SphereRegion::contains(const Vec3& x) const {
  const Vec3 d = x - center;
  return dot(d, d) <= radius * radius;
}

void SphereRegion::clip(const Vec3& o, const Vec3& v, double* a, double* b) const {
  const Vec3 oc = center - o;
  const double tc = dot(oc, v);
  const Vec3 perp = oc - tc * v;
  const double h2 = radius * radius - dot(perp, perp);
  if (!(h2 > 0.0)) {
    *b = *a;
    return;
  }
  const double h = std::sqrt(h2);
  *a = std::max(*a, tc - h);
  *b = std::min(*b, tc + h);
}

}  // namespace beamcast
