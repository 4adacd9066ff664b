// Light "spot": a point light at `position` shining along `direction`; full
// intensity within `inner_deg` of the axis, falling smoothly (smoothstep in
// cos angle) to zero at `outer_deg`. Its flux is what it emits in all.
#pragma once

#include <string_view>

#include "protocol/lights/light_base.hpp"

namespace beamcast {

struct SpotLight {
  static constexpr std::string_view kType = "spot";
  static constexpr std::array<std::string_view, 4> kFields{"position", "direction", "inner_deg",
                                                           "outer_deg"};
  Vec3 position{};
  Vec3 direction{0.0, -1.0, 0.0};  // unit
  double inner_deg = 20.0;
  double outer_deg = 30.0;
  double cos_inner = 0.0;  // derived
  double cos_outer = 0.0;
  double solid_angle_weight = 1.0;  // integral of the falloff over the sphere (sr)

  static SpotLight parse(const LightParse& in);
  // The falloff s in [0, 1] at cos(angle to the axis) c.
  double falloff(double c) const;
  Aabb bounds() const;
  Emission emit(const LightRandom& u) const;
  LightSample sample(const Vec3& x, const LightRandom& u) const;
  std::optional<double> hit(const Vec3& o, const Vec3& v, double t_max) const;
  std::vector<DirectPoint> direct_points(int samples) const;
  double radiance_scale() const { return 0.0; }
  // A point: never seen.
  std::optional<LightOutline> outline() const { return std::nullopt; }
  void outline_triangles(TriangleSink& /*sink*/) const {}
  void cache_key(LightKey& k) const;
};

}  // namespace beamcast
