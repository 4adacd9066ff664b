// Light "point": an isotropic point light at `position`.
#pragma once

#include <string_view>

#include "protocol/lights/light_base.hpp"

namespace beamcast {

struct PointLight {
  static constexpr std::string_view kType = "point";
  static constexpr std::array<std::string_view, 1> kFields{"position"};
  Vec3 position{};

  static PointLight parse(const LightParse& in);
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
