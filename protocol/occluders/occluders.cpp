#include "protocol/occluders/occluders.hpp"

#include <limits>
#include <optional>
#include <utility>

#include "protocol/occluders/occluder_parse.hpp"

namespace beamcast {

namespace {

// Calls f(std::type_identity<K>{}) for every kind K of OccluderShape, in order.
template <class F, std::size_t... I>
void each_kind(F&& f, std::index_sequence<I...>) {
  (f(std::type_identity<std::variant_alternative_t<I, OccluderShape>>{}), ...);
}
template <class F>
void each_kind(F&& f) {
  each_kind(std::forward<F>(f), std::make_index_sequence<std::variant_size_v<OccluderShape>>{});
}

}  // namespace

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
  fields.allow_only(all);
}

std::vector<std::string_view> occluder_types() {
  std::vector<std::string_view> types;
  each_kind([&](auto kind) { types.push_back(decltype(kind)::type::kType); });
  return types;
}

OccluderShape parse_occluder_shape(const std::string& type, const std::string& type_path,
                                   const OccluderParse& in) {
  std::optional<OccluderShape> shape;
  each_kind([&](auto kind) {
    using Kind = typename decltype(kind)::type;
    if (!shape && type == Kind::kType) shape.emplace(Kind::parse(in));
  });
  if (shape) return std::move(*shape);
  std::string allowed;
  for (std::string_view t : occluder_types()) {
    allowed += allowed.empty() ? "\"" : ", \"";
    allowed += t;
    allowed += '"';
  }
  json_read::fail("invalid_value", type_path,
                  "type must be one of " + allowed + ", got " +
                      json_read::describe(nlohmann::json(type)));
}

}  // namespace beamcast
