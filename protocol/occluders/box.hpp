// Occluder "box": an oriented box, rasterized as 12 two-sided triangles.
#pragma once

#include "protocol/occluders/occluder_base.hpp"

namespace beamcast {

struct BoxOccluder {
  static constexpr std::string_view kType = "box";
  static constexpr GpuForm kGpu = GpuForm::kTriangles;
  Vec3 center{};
  Vec3 size{1.0, 1.0, 1.0};                    // full edge lengths
  std::array<double, 4> rotation{1, 0, 0, 0};  // unit quaternion w, x, y, z

  static BoxOccluder parse(const OccluderParse& in);
  Aabb bounds() const;
  void gpu_triangles(TriangleSink& out) const;
  // Entry face, or the exit face for a ray that starts inside.
  std::optional<OccluderHit> intersect(const Vec3& o, const Vec3& v, double t_min,
                                       double t_max) const;

 private:
  std::array<Vec3, 8> corners() const;  // world space, corner i at (+-x, +-y, +-z) by bits of i
};

}  // namespace beamcast
