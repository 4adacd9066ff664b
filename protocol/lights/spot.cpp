#include "protocol/lights/spot.hpp"

#include <cmath>
#include <numbers>

#include "protocol/lights/light_parse.hpp"
#include "protocol/lights/sampling.hpp"

namespace beamcast {

using namespace json_read;

SpotLight SpotLight::parse(const LightParse& in) {
  SpotLight l;
  l.position = read_point(in.fields.required("position"), in.limits);
  l.direction = normalize(read_direction(in.fields.required("direction")));
  if (auto a = in.fields.optional("outer_deg")) {
    l.outer_deg = read_number(*a);
    if (!(l.outer_deg > 0.0 && l.outer_deg <= 180.0)) {
      fail("out_of_range", a->path, "outer_deg must be in (0, 180], got " + format_number(l.outer_deg));
    }
  }
  if (auto a = in.fields.optional("inner_deg")) {
    l.inner_deg = read_number(*a);
    if (!(l.inner_deg >= 0.0 && l.inner_deg <= l.outer_deg)) {
      fail("out_of_range", a->path,
           "inner_deg must be in [0, outer_deg = " + format_number(l.outer_deg) + "], got " +
               format_number(l.inner_deg));
    }
  } else {
    l.inner_deg = std::min(l.inner_deg, l.outer_deg);
  }
  const double deg = std::numbers::pi / 180.0;
  l.cos_inner = std::cos(l.inner_deg * deg);
  l.cos_outer = std::cos(l.outer_deg * deg);
  // Integral of the falloff over solid angle, 2 pi * integral over c =
  // cos(angle) of s(c): 1 on [cos_inner, 1] and smoothstep's mean (1/2) over
  // [cos_outer, cos_inner].
  l.solid_angle_weight =
      2.0 * std::numbers::pi * ((1.0 - l.cos_inner) + 0.5 * (l.cos_inner - l.cos_outer));
  return l;
}

double SpotLight::falloff(double c) const {
  if (c >= cos_inner) return 1.0;
  if (c <= cos_outer) return 0.0;
  const double t = (c - cos_outer) / (cos_inner - cos_outer);
  return t * t * (3.0 - 2.0 * t);
}

Aabb SpotLight::bounds() const {
  Aabb b;
  b.grow(position);
  return b;
}

Emission SpotLight::emit(const LightRandom& u) const {
  // Uniform over the outer cone (solid angle 2 pi (1 - cos_outer)); the
  // falloff, normalized by its integral, weights the photon.
  const Vec3 dir = uniform_cone(direction, cos_outer, u[0], u[1]);
  const double cone = 2.0 * std::numbers::pi * (1.0 - cos_outer);
  return {position, dir, falloff(dot(dir, direction)) * cone / solid_angle_weight};
}

LightSample SpotLight::sample(const Vec3& x, const LightRandom& /*u*/) const {
  const Vec3 d = position - x;
  const double dist = length(d);
  if (!(dist > 0.0)) return {};
  const Vec3 dir = (1.0 / dist) * d;
  // Intensity per unit flux: falloff / its integral over the sphere.
  return {position, dir, dist, falloff(-dot(dir, direction)) / (solid_angle_weight * dist * dist)};
}

std::optional<double> SpotLight::hit(const Vec3&, const Vec3&, double) const {
  return std::nullopt;
}

std::vector<DirectPoint> SpotLight::direct_points(int /*samples*/) const {
  DirectPoint p;
  p.position = position;
  p.axis = direction;
  p.mode = DirectPoint::Mode::kCone;
  p.scale = 1.0 / solid_angle_weight;
  p.cos_inner = cos_inner;
  p.cos_outer = cos_outer;
  return {p};
}

void SpotLight::cache_key(LightKey& k) const {
  k.put(position);
  k.put(direction);
  k.put(inner_deg);
  k.put(outer_deg);
}

}  // namespace beamcast
