// Medium region "sphere": a ball about its center of its radius.
// GPU record: code 1, a = center, r = radius.
#pragma once

#include "protocol/media/region_base.hpp"

namespace beamcast {

struct SphereRegion : ConvexRegion<SphereRegion> {
  static constexpr std::string_view kType = "sphere";
  static constexpr std::array<std::string_view, 2> kFields{"center", "radius"};
  static constexpr int kGpuCode = 1;
  Vec3 center{};
  double radius = 0.0;

  static SphereRegion parse(const RegionParse& in);
  Aabb bounds() const;
  bool contains(const Vec3& x) const;
  void clip(const Vec3& o, const Vec3& v, double* a, double* b) const;
  RegionGpu gpu() const { return {kGpuCode, center, Vec3{}, radius}; }
};

}  // namespace beamcast
