// Medium region "cylinder": fog shaped like a beam, the points within
// `radius` of the axis segment from p0 to p1, between the two flat caps
// through p0 and p1 perpendicular to it. GPU record: code 3, a = p0,
// b = p1, r = radius.
#pragma once

#include "protocol/media/region_base.hpp"

namespace beamcast {

struct CylinderRegion : ConvexRegion<CylinderRegion> {
  static constexpr std::string_view kType = "cylinder";
  static constexpr std::array<std::string_view, 3> kFields{"p0", "p1", "radius"};
  static constexpr int kGpuCode = 3;
  Vec3 p0{};
  Vec3 p1{};
  double radius = 0.0;

  // p0 and p1 within max_abs_coordinate and apart (also in float, as the
  // GPU holds them); radius a size (read_size).
  static CylinderRegion parse(const RegionParse& in);
  Aabb bounds() const;
  bool contains(const Vec3& x) const;
  void clip(const Vec3& o, const Vec3& v, double* a, double* b) const;
  RegionGpu gpu() const { return {kGpuCode, p0, p1, radius}; }
};

}  // namespace beamcast
