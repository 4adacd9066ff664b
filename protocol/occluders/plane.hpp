// Occluder "plane": an infinite plane through `point` with `normal`,
// ray-traced per pixel on the GPU, visible from both sides.
#pragma once

#include "protocol/occluders/occluder_base.hpp"

namespace beamcast {

struct PlaneOccluder {
  static constexpr std::string_view kType = "plane";
  static constexpr GpuForm kGpu = GpuForm::kAnalytic;
  Vec3 point{};
  Vec3 normal{0.0, 1.0, 0.0};  // nonzero, need not be unit

  static PlaneOccluder parse(const OccluderParse& in);
  Aabb bounds() const;  // unbounded: -inf .. +inf
  AnalyticGpu analytic(const Vec3& eye) const;
  std::optional<OccluderHit> intersect(const Vec3& o, const Vec3& v, double t_min,
                                       double t_max) const;
};

}  // namespace beamcast
