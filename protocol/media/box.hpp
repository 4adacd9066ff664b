// Medium region "box": axis-aligned, between its corners min and max.
// GPU record: code 0, a = min, b = max.
#pragma once

#include "protocol/media/region_base.hpp"

namespace beamcast {

struct BoxRegion : ConvexRegion<BoxRegion> {
  static constexpr std::string_view kType = "box";
  static constexpr std::array<std::string_view, 2> kFields{"min", "max"};
  static constexpr int kGpuCode = 0;
  Vec3 lo{};
  Vec3 hi{};

  static BoxRegion parse(const RegionParse& in);
  Aabb bounds() const { return Aabb{lo, hi}; }
  bool contains(const Vec3& x) const;
  void clip(const Vec3& o, const Vec3& v, double* a, double* b) const;
  RegionGpu gpu() const { return {kGpuCode, lo, hi, 0.0}; }
};

}  // namespace beamcast
