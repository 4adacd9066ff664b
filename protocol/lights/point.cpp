#include "protocol/lights/point.hpp"

#include <numbers>

#include "protocol/lights/light_parse.hpp"
#include "protocol/lights/sampling.hpp"

namespace beamcast {

PointLight PointLight::parse(const LightParse& in) {
  PointLight l;
  l.position = json_read::read_point(in.fields.required("position"), in.limits);
  return l;
}

Aabb PointLight::bounds() const {
  Aabb b;
  b.grow(position);
  return b;
}

Emission PointLight::emit(const LightRandom& u) const {
  return {position, uniform_sphere(u[0], u[1]), 1.0};
}

LightSample PointLight::sample(const Vec3& x, const LightRandom& /*u*/) const {
  const Vec3 d = position - x;
  const double dist = length(d);
  if (!(dist > 0.0)) return {};
  return {position, (1.0 / dist) * d, dist, 1.0 / (4.0 * std::numbers::pi * dist * dist)};
}

std::optional<double> PointLight::hit(const Vec3&, const Vec3&, double) const {
  return std::nullopt;  // a point is never seen
}

void PointLight::cache_key(LightKey& k) const { k.put(position); }

std::vector<DirectPoint> PointLight::direct_points(int /*samples*/) const {
  DirectPoint p;
  p.position = position;
  p.scale = 1.0 / (4.0 * std::numbers::pi);
  return {p};
}

}  // namespace beamcast
