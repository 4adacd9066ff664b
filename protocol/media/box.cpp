#include "protocol/media/box.hpp"

#include "protocol/json_reader.hpp"
#include "protocol/scene_json.hpp"

namespace beamcast {

BoxRegion BoxRegion::parse(const RegionParse& in) {
  const double max_abs = in.opts.limits.max_abs_coordinate;
  BoxRegion r;
  const json_read::Node lo = in.fields.required("min");
  r.lo = json_read::check_coordinates(lo, json_read::read_vec3(lo), max_abs);
  const json_read::Node hi = in.fields.required("max");
  r.hi = json_read::check_coordinates(hi, json_read::read_vec3(hi), max_abs);
  for (std::size_t i = 0; i < 3; ++i) {
    if (!(r.hi[i] > r.lo[i])) {
      json_read::fail("invalid_value", hi.path,
                      "max must exceed min in every coordinate (an empty box)");
    }
  }
  return r;
}

bool BoxRegion::contains(const Vec3& x) const {
  return x[0] >= lo[0] && x[0] <= hi[0] && x[1] >= lo[1] && x[1] <= hi[1] && x[2] >= lo[2] &&
         x[2] <= hi[2];
}

void BoxRegion::clip(const Vec3& o, const Vec3& v, double* a, double* b) const {
  clip_to_box(bounds(), o, v, a, b);
}

}  // namespace beamcast
