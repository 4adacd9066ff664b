// Occluder "sphere": ray-traced per pixel on the GPU.
#pragma once

#include "protocol/occluders/occluder_base.hpp"

namespace beamcast {

struct SphereOccluder {
  static constexpr std::string_view kType = "sphere";
  static constexpr GpuForm kGpu = GpuForm::kAnalytic;
  Vec3 center{};
  double radius = 1.0;

  static SphereOccluder parse(const OccluderParse& in);
  Aabb bounds() const;
  AnalyticGpu analytic(const Vec3& eye) const;
  // The nearer crossing in [t_min, t_max], else the farther one (a ray that
  // starts inside the sphere sees its inside).
  std::optional<OccluderHit> intersect(const Vec3& o, const Vec3& v, double t_min,
                                       double t_max) const;
};

}  // namespace beamcast
