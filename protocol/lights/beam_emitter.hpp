// Light "beam": not a kind a client writes in "lights", but the light a beam
// with "emit": true gives off (issue 14, item 1). The parser appends one per
// emitting beam to Scene::lights (kDerived), so the photon tracer, the path
// tracer, the CPU gather and the direct pass light a room with it as with any
// other light, through the same contract (light_base.hpp).
//
// Radiometry. A beam's glow is emission without absorption: the radiance a
// ray collects is color x intensity x the line integral of f(dist / radius)
// measured in radii (docs/scene-format.md, "Units"), so the beam emits, per
// unit volume and solid angle, eps(y) = color x intensity x f(x(y)) / radius,
// isotropically. Its flux is therefore 4 pi x color x intensity x M / radius
// with M = the volume integral of f (Light::flux); photons leave points
// drawn with density proportional to f, in uniform directions.
//   sphere:  M = 4 pi r^3 S2;  capsule: M = 4 pi r^3 S2 + 2 pi r^2 L S1,
//   Sk = integral over [0, 1] of f(x) x^k dx.
// Direct pass: a sphere is one isotropic point at its centre, exact (as a
// point mass by the shell theorem) wherever the surface sees the whole
// sphere above its horizon; a capsule is points along its axis for the
// cylinder's mass and one point per cap at that half-ball's centroid.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "protocol/beams/beams.hpp"
#include "protocol/density.hpp"
#include "protocol/lights/light_base.hpp"

namespace beamcast {

// Radial moments and sampling tables of one density (shared by copies).
struct RadialMass {
  double s1 = 0.0, s2 = 0.0, s3 = 0.0;  // integrals of f(x) x^k over [0, 1]
  // Cumulative integrals of f(x) x (cdf1) and f(x) x^2 (cdf2) at the ends
  // of kCells equal cells, normalized to end at 1.
  std::vector<double> cdf1, cdf2;
  static constexpr int kCells = 4096;
  explicit RadialMass(const Density& f);
  // x in [0, 1] with density proportional to f(x) x^k (k = 1 or 2).
  double sample(int k, double u) const;
};

struct BeamEmitter {
  static constexpr std::string_view kType = "beam";
  static constexpr bool kDerived = true;  // made from a beam, never parsed
  BeamShape shape;
  double radius = 1.0;
  std::shared_ptr<const RadialMass> mass;
  std::string density_key;  // Density::key(), for cache keys
  int beam = -1;            // index in Scene::beams

  // The emitter of a beam, and the volume integral M of its density.
  static BeamEmitter from_beam(const BeamShape& shape, double radius, const Density& density,
                               int beam_index);
  double volume_mass() const;

  Aabb bounds() const;
  Emission emit(const LightRandom& u) const;
  LightSample sample(const Vec3& x, const LightRandom& u) const;
  std::optional<double> hit(const Vec3& o, const Vec3& v, double t_max) const;
  std::vector<DirectPoint> direct_points(int samples) const;
  double radiance_scale() const { return 0.0; }
  // Its glow is drawn by the beam pass, not as a seen emitter.
  std::optional<LightOutline> outline() const { return std::nullopt; }
  void outline_triangles(TriangleSink& /*sink*/) const {}
  void cache_key(LightKey& k) const;

 private:
  Vec3 sample_point(const LightRandom& u) const;
};

}  // namespace beamcast
