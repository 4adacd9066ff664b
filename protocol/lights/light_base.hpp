// What every light kind provides to the parser, the photon tracer, the CPU
// path tracer (gi/) and the GPU passes (render/). A kind is one struct in its
// own files here (point, spot, quad, beam_emitter) holding its geometry; the
// emitted flux (color x power) stays in Light (scene.hpp) and is passed in:
//   static constexpr std::string_view kType;   its "type" in scene JSON
//   static constexpr std::array kFields;       its own JSON keys ("radiance"
//                                              among them: the flux may be
//                                              given as radiance instead)
//   static T parse(const LightParse& in);      validation, JSON-pointer errors
//   Aabb bounds() const;
//   Emission emit(u) const;                    a photon's origin and direction
//   LightSample sample(x, u) const;            next-event estimation towards x
//   std::optional<double> hit(o, v, t_max) const;   rays that see the emitter
//   double radiance_scale() const;             emitted radiance per unit flux
//   std::vector<DirectPoint> direct_points(n) const;  the points the raster
//                                              direct-light pass shades from
//   std::optional<LightOutline> outline() const;  what a camera sees of it
//                                              (none: never seen)
//   void outline_triangles(TriangleSink&) const;  the same, as one-sided
//                                              triangles for the raster G-buffer
//   void cache_key(LightKey&) const;           the numbers its emission and
//                                              outline depend on (caches)
// Dispatch over the kinds is std::visit over LightShape (lights.hpp): a kind
// that lacks a member fails to compile where it is needed.
// Radiometry: flux in watts per channel; a point light's intensity is
// flux / 4 pi; a spot's falls from the inner to the outer cone and its
// total over the sphere is the flux; a quad is a one-sided Lambertian emitter
// with radiance flux / (pi area).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "protocol/occluders/occluder_base.hpp"
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

// What a camera sees of a light (the G-buffer, gi_resolve's outline
// antialiasing, the GPU's specular rays; the CPU path tracer uses hit()): a
// flat one-sided emitter of constant radiance (radiance_scale() x flux),
// seen from the side `normal` (unit, along cross(u, v)) points to. Its
// emitting part lies inside the parallelogram corner + a u + b v (a, b in
// [0, 1]); `code` tells the shaders which part (shaders/light_outline.glsl:
// the kind's kOutlineCode; 1 all of it, the quad).
struct LightOutline {
  int code = 0;
  Vec3 corner{};
  Vec3 u{};
  Vec3 v{};
  Vec3 normal{};
};

// The bytes of the numbers a light's emission and outline depend on: the
// photon cache's key (gi/photon_cache.cpp) and the render side's geometry key.
struct LightKey {
  std::string bytes;
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void text(std::string_view s) { bytes.append(s); }
};

}  // namespace beamcast
