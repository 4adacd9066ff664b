// What every light kind provides to the parser, the photon tracer and the CPU
// path tracer (gi/). A kind is one struct in its own files here (point, spot,
// quad) holding its geometry; the emitted flux (color x power) stays in Light
// (scene.hpp) and is passed in:
//   static constexpr std::string_view kType;   its "type" in scene JSON
//   static constexpr std::array kFields;       its own JSON keys
//   static T parse(const LightParse& in);      validation, JSON-pointer errors
//   Aabb bounds() const;
//   Emission emit(u) const;                    a photon's origin and direction
//   LightSample sample(x, u) const;            next-event estimation towards x
//   std::optional<double> hit(o, v, t_max) const;   rays that see the emitter
//   double radiance_scale() const;             emitted radiance per unit flux
//   std::vector<DirectPoint> direct_points(n) const;  the points the raster
//                                              direct-light pass shades from
// Dispatch over the kinds is std::visit over LightShape (lights.hpp).
// Radiometry: flux in watts per channel; a point light's intensity is
// flux / 4 pi; a spot's falls from the inner to the outer cone and its
// total over the sphere is the flux; a quad is a one-sided Lambertian emitter
// with radiance flux / (pi area).
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "protocol/vec.hpp"

namespace beamcast {

struct LightParse;  // light_parse.hpp

// Four uniform numbers in [0, 1) for one sample.
using LightRandom = std::array<double, 4>;

// Where a photon leaves the light, its unit direction, and the factor its
// share of the flux is scaled by (1 for lights that emit uniformly over the
// sampled set; the spot's falloff otherwise; mean 1 over samples).
struct Emission {
  Vec3 origin{};
  Vec3 dir{0.0, 0.0, 1.0};
  double weight = 1.0;
};

// Next-event estimation from a surface point x: the light point y, the unit
// direction from x to y, its distance, and the factor G such that the
// irradiance at x from this sample, per unit flux of the light, is
// G * max(0, n_x . dir) (point: 1/(4 pi d^2); quad: cos_y / (pi A d^2) / pdf).
struct LightSample {
  Vec3 y{};
  Vec3 dir{};
  double dist = 0.0;
  double g = 0.0;  // 0: the light does not shine towards x
};

// One point the GPU's direct-light pass (shadow-mapped, render/passes.cpp)
// treats as a point emitter: the irradiance at x from it, per unit flux of
// its light, is scale * angular(c) / d^2 * max(0, n_x . l), with c the cosine
// between `axis` and the direction from the point to x and angular(c):
//   kIsotropic: 1;  kCosine: max(0, c) (one-sided area-light patch);
//   kCone: the spot's smoothstep falloff between cos_outer and cos_inner.
// A light's points together give its irradiance exactly for a point light or
// a spot, and as a stratified quadrature over the area for a quad.
struct DirectPoint {
  enum class Mode { kIsotropic = 0, kCosine = 1, kCone = 2 };
  Vec3 position{};
  Vec3 axis{0.0, 0.0, 0.0};
  Mode mode = Mode::kIsotropic;
  double scale = 0.0;
  double cos_inner = 1.0;
  double cos_outer = 1.0;
};

}  // namespace beamcast
