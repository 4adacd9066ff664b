#include "protocol/media/regions.hpp"

#include <algorithm>
#include <utility>

#include "protocol/json_reader.hpp"
#include "protocol/kinds.hpp"

namespace beamcast {

namespace {

// The keys every region has besides its kind's own.
constexpr std::string_view kCoefficientFields[] = {"sigma_s", "sigma_a", "k", "g"};

// "type", the kind's fields, then the coefficients.
template <class K>
std::vector<std::string_view> kind_fields() {
  std::vector<std::string_view> keys{"type"};
  keys.insert(keys.end(), K::kFields.begin(), K::kFields.end());
  keys.insert(keys.end(), std::begin(kCoefficientFields), std::end(kCoefficientFields));
  return keys;
}

}  // namespace

void clip_to_box(const Aabb& box, const Vec3& o, const Vec3& v, double* a, double* b) {
  for (std::size_t i = 0; i < 3; ++i) {
    if (v[i] == 0.0) {
      if (o[i] < box.lo[i] || o[i] > box.hi[i]) *b = *a;
      continue;
    }
    const double ta = (box.lo[i] - o[i]) / v[i], tb = (box.hi[i] - o[i]) / v[i];
    *a = std::max(*a, std::min(ta, tb));
    *b = std::min(*b, std::max(ta, tb));
  }
}

std::vector<std::string_view> medium_region_types() { return kind_types<RegionShape>(); }

std::vector<std::string_view> medium_region_fields() {
  std::vector<std::string_view> keys{"type"};
  each_kind<RegionShape>([&](auto kind) {
    for (std::string_view f : decltype(kind)::type::kFields) {
      if (std::find(keys.begin(), keys.end(), f) == keys.end()) keys.push_back(f);
    }
  });
  keys.insert(keys.end(), std::begin(kCoefficientFields), std::end(kCoefficientFields));
  return keys;
}

RegionShape parse_region_shape(const json_read::Node& type, const RegionParse& in) {
  return parse_kind<RegionShape>(type, [&](auto kind) {
    using K = typename decltype(kind)::type;
    in.fields.allow_only(std::span<const std::string_view>(kind_fields<K>()));
    return K::parse(in);
  });
}

}  // namespace beamcast
