// Light "quad": a one-sided Lambertian emitting parallelogram corner + a
// edge_u + b edge_v (a, b in [0, 1]), emitting to the side cross(edge_u,
// edge_v) points to (the Cornell box's ceiling light faces down). Its
// radiance is flux / (pi area); "radiance" in JSON gives it directly.
#pragma once

#include <string_view>

#include "protocol/lights/light_base.hpp"

namespace beamcast {

struct QuadLight {
  static constexpr std::string_view kType = "quad";
  static constexpr std::array<std::string_view, 4> kFields{"corner", "edge_u", "edge_v",
                                                           "radiance"};
  // shaders/light_outline.glsl: the whole parallelogram.
  static constexpr int kOutlineCode = 1;
  Vec3 corner{};
  Vec3 edge_u{1.0, 0.0, 0.0};
  Vec3 edge_v{0.0, 0.0, 1.0};
  Vec3 normal{0.0, 1.0, 0.0};  // unit, derived
  double area = 1.0;           // derived

  static QuadLight parse(const LightParse& in);
  Aabb bounds() const;
  Emission emit(const LightRandom& u) const;
  LightSample sample(const Vec3& x, const LightRandom& u) const;
  std::optional<double> hit(const Vec3& o, const Vec3& v, double t_max) const;
  // A k_u x k_v grid of cell centres (direct_points), listed 2 x 2 cell by
  // 2 x 2 cell, so that with both even every fourth point (the direct pass's
  // interleaved quarters, gi.direct_interleave) spans the whole light.
  std::vector<DirectPoint> direct_points(int samples) const;
  double radiance_scale() const;
  std::optional<LightOutline> outline() const;
  void outline_triangles(TriangleSink& sink) const;
  void cache_key(LightKey& k) const;
};

}  // namespace beamcast
