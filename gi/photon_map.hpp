// Photon tracing on the CPU (seed 001, chapter 2; issue 14, item 2): photons
// leave the scene's lights, bounce off surfaces with Russian roulette on
// their reflectance, reflect off mirrors and reflect or refract at glass by
// Fresnel, and are stored where they hit a diffuse surface. Two maps: the
// global map (every diffuse hit, except L S+ D paths when a caustic map is
// traced) and the caustic map (the first diffuse hit after one or more
// specular bounces straight from the light). In a medium (Scene::medium,
// issue 15) photons fly free paths d = -ln xi / sigma_t between events,
// are absorbed with probability 1 - sigma_s / sigma_t at each, else scatter
// by Schlick's phase function and are stored in the volume map; the caustic
// map's paths end at their first scattering. Multi-threaded; for one seed
// the maps are identical whatever the thread count. Cancellable
// (protocol/cancel.hpp: checked every 64 photons) and bounded in the
// events stored (gi.max_photon_events, PhotonEventLimit).
#pragma once

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "gi/gi_scene.hpp"
#include "protocol/scene.hpp"

namespace beamcast {

struct Photon {
  float p[3];      // where it hit (volume map: where it scattered)
  float power[3];  // flux it carries (watts per channel)
  float dir[3];    // unit travel direction when it arrived
  float n[3];      // unit normal of the surface it hit, facing where it came from (volume: 0)
  // Surface interactions before this one: 0 = straight from the light (direct light).
  std::uint16_t bounces;
  // Set for L S+ D paths (only specular bounces before this hit).
  std::uint16_t caustic;
};

struct PhotonMaps {
  std::vector<Photon> global;
  std::vector<Photon> caustic;
  // Scattering events in the medium of the global map's paths (their power
  // as they arrived): sum p(mu) power / volume estimates sigma_s times the
  // in-scattered radiance.
  std::vector<Photon> volume;
  std::int64_t emitted_global = 0;   // photons sent into the scene for each map
  std::int64_t emitted_caustic = 0;
  double trace_ms = 0.0;             // wall time of tracing both
};

// Thrown by trace_photons when the maps would store more than
// gi.max_photon_events events (SceneLimits::max_photon_events): tracing
// stops there and what was stored is freed.
class PhotonEventLimit : public std::runtime_error {
 public:
  PhotonEventLimit(std::int64_t limit, std::int64_t photons_traced)
      : std::runtime_error("photon tracing stored more than max_photon_events = " +
                           std::to_string(limit) + " events (surface hits and medium "
                           "scatterings) by photon " + std::to_string(photons_traced) +
                           " of a map: lower gi.photons or gi.max_depth, or thin the medium"),
        limit_(limit) {}
  std::int64_t limit() const { return limit_; }

 private:
  std::int64_t limit_;
};

struct PhotonTraceOptions {
  int threads = 0;  // 0: std::thread::hardware_concurrency()
};

// Traces scene.gi.photons photons for the global map and, if the scene has a
// mirror or glass occluder, scene.gi.caustic_photons for the caustic map.
// Each photon carries flux / (emitted x probability of its light), so the
// powers of one map's photons sum, in expectation, to what reaches the
// surfaces.
PhotonMaps trace_photons(const Scene& scene, const GiScene& surfaces,
                         const PhotonTraceOptions& options = {});

// Whether any occluder is a mirror or glass (a caustic map is traced).
bool has_specular(const Scene& scene);

// The splat / gather radius when gi.radius is 0: with the global map's
// photons spread evenly over the six faces of the scene's bounding box, 800
// photons per disk at 1e5 photons when the direct pass carries direct light
// (50 when photons do), and r proportional to photons^(-1/6) (the
// bias-variance balance of a 2D density estimate).
double default_photon_radius(const Scene& scene, std::int64_t photons);

// The volume photons' kernel radius when medium.radius is 0: `volume_photons`
// stored photons spread evenly through the bounding box of the occluders and
// lights, 50 in each kernel sphere.
double default_volume_radius(const Scene& scene, std::int64_t volume_photons);

// The caustic map's splat radius when gi.caustic_radius is 0: the same rule
// with 200 photons per disk (50 when photons carry direct light) at the
// caustic photon count (gi.caustic_photons, or the share drawn), times
// kCausticRadiusScale. Caustic photons
// crowd into the small regions light is focused on, far denser than the
// global map's even spread, so a smaller disk holds as many; and the
// focus is sharp, so a disk the global map's size blurs it (docs/gi.md).
inline constexpr double kCausticRadiusScale = 0.25;
double default_caustic_radius(const Scene& scene, std::int64_t caustic_photons);

// The share of each map the photon pass draws: GiSettings::display_fraction
// kept in [1e-3, 1] (the draws and the radii take the same share).
inline double display_share(double display_fraction) {
  return std::clamp(display_fraction, 1e-3, 1.0);
}

// The radii the splat pass uses for the global and the caustic map: the
// scene's gi.radius / gi.caustic_radius, or the defaults at the photon
// counts drawn (a share `drawn` of each map, gi.display_fraction).
struct SplatRadii {
  double global = 0.0;
  double caustic = 0.0;
};
SplatRadii splat_radii(const Scene& scene, double drawn = 1.0);

}  // namespace beamcast
