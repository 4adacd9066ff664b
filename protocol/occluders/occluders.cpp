#include "protocol/occluders/occluders.hpp"

#include <limits>
#include <utility>

#include "protocol/kinds.hpp"
#include "protocol/occluders/occluder_parse.hpp"

namespace beamcast {

bool ray_box(const Vec3& o, const Vec3& v, const Aabb& box, double* t_near, double* t_far,
             int* axis_near, int* axis_far) {
  *t_near = -std::numeric_limits<double>::infinity();
  *t_far = std::numeric_limits<double>::infinity();
  *axis_near = *axis_far = -1;
  for (int k = 0; k < 3; ++k) {
    if (v[k] == 0.0) {
      if (o[k] < box.lo[k] || o[k] > box.hi[k]) return false;
      continue;
    }
    const double inv = 1.0 / v[k];
    double ta = (box.lo[k] - o[k]) * inv;
    double tb = (box.hi[k] - o[k]) * inv;
    if (ta > tb) std::swap(ta, tb);
    if (ta > *t_near) *t_near = ta, *axis_near = k;
    if (tb < *t_far) *t_far = tb, *axis_far = k;
  }
  return *t_near <= *t_far;
}

void OccluderParse::allow(std::initializer_list<std::string_view> kind_fields) const {
  std::vector<std::string_view> all{"type"};
  all.insert(all.end(), kind_fields.begin(), kind_fields.end());
  all.push_back("albedo");
  all.push_back("material");
  fields.allow_only(all);
}

std::vector<std::string_view> occluder_types() { return kind_types<OccluderShape>(); }

OccluderShape parse_occluder_shape(const json_read::Node& type, const OccluderParse& in) {
  return parse_kind<OccluderShape>(type,
                                   [&](auto kind) { return decltype(kind)::type::parse(in); });
}

}  // namespace beamcast
