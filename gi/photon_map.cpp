#include "gi/photon_map.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <thread>
#include <variant>

#include "gi/optics.hpp"
#include "gi/parallel.hpp"
#include "gi/phase.hpp"
#include "protocol/cancel.hpp"
#include "protocol/lights/sampling.hpp"
#include "protocol/scene_bounds.hpp"

namespace beamcast {
namespace {

// Photons per unit of work: a chunk is traced by one thread with its own
// random sequence, seeded by (seed, map, chunk), so the result does not
// depend on which thread took which chunk.
constexpr std::int64_t kChunk = 4096;

class Random {
 public:
  Random(std::uint64_t seed, std::uint32_t map, std::uint64_t chunk) {
    std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32), map,
                      static_cast<std::uint32_t>(chunk), static_cast<std::uint32_t>(chunk >> 32)};
    rng_.seed(seq);
  }
  // Uniform in [0, 1), the same on every platform (53 bits of the generator).
  double next() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }

 private:
  std::mt19937_64 rng_;
};

double luminance(const Color& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

// Lights chosen in proportion to their flux's luminance (all equal if none has any).
struct LightChoice {
  std::vector<double> cdf;
  std::vector<double> prob;
  explicit LightChoice(const Scene& s) {
    double total = 0.0;
    for (const Light& l : s.lights) total += luminance(l.flux);
    double acc = 0.0;
    for (const Light& l : s.lights) {
      const double p = total > 0.0 ? luminance(l.flux) / total : 1.0 / s.lights.size();
      prob.push_back(p);
      acc += p;
      cdf.push_back(acc);
    }
  }
  std::size_t pick(double u) const {
    const auto it = std::upper_bound(cdf.begin(), cdf.end(), u * cdf.back());
    return std::min<std::size_t>(static_cast<std::size_t>(it - cdf.begin()), cdf.size() - 1);
  }
};

enum class MapKind : std::uint32_t { kGlobal = 0, kCaustic = 1 };

Photon make_photon(const SurfaceHit& h, const Vec3& dir, const Color& power, int bounces,
                   bool caustic) {
  Photon ph{};
  for (int k = 0; k < 3; ++k) {
    ph.p[k] = static_cast<float>(h.p[k]);
    ph.power[k] = static_cast<float>(power[k]);
    ph.dir[k] = static_cast<float>(dir[k]);
    ph.n[k] = static_cast<float>(h.n[k]);
  }
  ph.bounces = static_cast<std::uint16_t>(std::min(bounces, 65535));
  ph.caustic = caustic ? 1 : 0;
  return ph;
}

Color scale(const Color& a, const Color& b) { return {a[0] * b[0], a[1] * b[1], a[2] * b[2]}; }

Photon make_volume_photon(const Vec3& x, const Vec3& dir, const Color& power, int events) {
  Photon ph{};
  for (int k = 0; k < 3; ++k) {
    ph.p[k] = static_cast<float>(x[k]);
    ph.power[k] = static_cast<float>(power[k]);
    ph.dir[k] = static_cast<float>(dir[k]);
  }
  ph.bounces = static_cast<std::uint16_t>(std::min(events, 65535));
  return ph;
}

// One photon's path. `global_skips_caustics`: L S+ D hits are left to the
// caustic map. For the caustic map only L S+ D hits are stored, and the path
// ends at its first diffuse hit (or scattering in the medium). Scattering
// events go to `volume` (global map only).
void trace_one(const Scene& scene, const GiScene& surfaces, const LightChoice& lights,
               std::int64_t emitted, MapKind map, bool global_skips_caustics, Random& rng,
               std::vector<Photon>* out, std::vector<Photon>* volume) {
  const std::size_t li = lights.pick(rng.next());
  const Light& light = scene.lights[li];
  const LightRandom u{rng.next(), rng.next(), rng.next(), rng.next()};
  const Emission e = std::visit([&](const auto& kind) { return kind.emit(u); }, light.shape);
  if (e.weight <= 0.0) return;
  Color power = (e.weight / (static_cast<double>(emitted) * lights.prob[li])) * light.flux;
  Vec3 o = e.origin;
  Vec3 d = e.dir;
  const double eps = surfaces.epsilon();
  bool specular_only = true;  // every bounce so far was specular (or none)
  const MediumField medium = scene.medium_field();
  for (int depth = 0; depth < scene.gi.max_depth; ++depth) {
    const auto hit = surfaces.intersect(o, d, eps, std::numeric_limits<double>::infinity());
    if (!medium.empty()) {
      // A free path sampled exactly against the local extinction
      // (MediumField::free_path): the medium fills space, so a photon that
      // meets no surface meets it, up to the medium's finite extent.
      const double t_hit = std::min(hit ? hit->t : std::numeric_limits<double>::infinity(),
                                    medium.last_exit(o, d));
      const double t = medium.free_path(o, d, t_hit, -std::log1p(-rng.next()));
      const bool event = t < t_hit;
      if (event) {
        if (map == MapKind::kCaustic) return;
        const Vec3 x = o + t * d;
        // Scattered with probability sigma_s / sigma_t there, else absorbed.
        if (!(rng.next() * medium.sigma_t(x) < medium.sigma_s(x))) return;
        o = x;
        volume->push_back(make_volume_photon(o, d, power, depth));
        const double u1 = rng.next();
        const double u2 = rng.next();
        d = schlick_sample_direction(medium.k(x), d, u1, u2);
        specular_only = false;
        continue;
      }
    }
    if (!hit || hit->light >= 0) return;  // leaves the scene, or absorbed by an emitter
    const Occluder& occ = scene.occluders[static_cast<std::size_t>(hit->occluder)];
    const Material& m = occ.material;
    if (m.type == MaterialType::kDiffuse) {
      const bool caustic = specular_only && depth > 0;
      if (map == MapKind::kCaustic) {
        if (caustic) out->push_back(make_photon(*hit, d, power, depth, true));
        return;
      }
      if (!(caustic && global_skips_caustics)) {
        out->push_back(make_photon(*hit, d, power, depth, caustic));
      }
      // Russian roulette on the albedo: survive with p = its mean, carry albedo / p.
      const double p = (occ.albedo[0] + occ.albedo[1] + occ.albedo[2]) / 3.0;
      if (!(rng.next() < p)) return;
      power = (1.0 / p) * scale(power, occ.albedo);
      const double u1 = rng.next();
      const double u2 = rng.next();
      d = cosine_hemisphere(hit->n, u1, u2);
      specular_only = false;
    } else if (m.type == MaterialType::kMirror) {
      if (map == MapKind::kCaustic && !specular_only) return;
      const double p = std::max({m.reflectance[0], m.reflectance[1], m.reflectance[2]});
      if (!(rng.next() < p)) return;
      power = (1.0 / p) * scale(power, m.reflectance);
      d = reflect(d, hit->n);
    } else {  // glass: the hit normal faces the incoming side
      if (map == MapKind::kCaustic && !specular_only) return;
      const double n1 = hit->entering ? 1.0 : m.ior;
      const double n2 = hit->entering ? m.ior : 1.0;
      const double f = fresnel_dielectric(-dot(d, hit->n), n1, n2);
      const auto t = refract(d, hit->n, n1, n2);
      if (!t || rng.next() < f) {
        d = reflect(d, hit->n);
      } else {
        d = normalize(*t);
        power = scale(power, m.tint);
      }
    }
    o = hit->p;
  }
}

// The chunks' photons in chunk order, each part freed once copied (the
// peak is the maps plus one chunk's part, not twice the maps).
std::vector<Photon> concatenate(std::vector<std::vector<Photon>>& parts) {
  std::size_t total = 0;
  for (const auto& p : parts) total += p.size();
  std::vector<Photon> all;
  all.reserve(total);
  for (auto& p : parts) {
    all.insert(all.end(), p.begin(), p.end());
    std::vector<Photon>().swap(p);
  }
  return all;
}

// Photons between checks of the cancel token within a chunk: in a dense
// medium a photon stores up to gi.max_depth events, so a 4096-photon chunk
// can take a while.
constexpr std::int64_t kCancelEvery = 64;

std::vector<Photon> trace_map(const Scene& scene, const GiScene& surfaces, std::int64_t count,
                              MapKind map, bool global_skips_caustics, int threads,
                              std::vector<Photon>* volume, std::atomic<std::int64_t>* stored) {
  const LightChoice lights(scene);
  const std::int64_t chunks = (count + kChunk - 1) / kChunk;
  std::vector<std::vector<Photon>> parts(static_cast<std::size_t>(chunks));
  std::vector<std::vector<Photon>> volume_parts(static_cast<std::size_t>(chunks));
  const std::int64_t cap = scene.gi.max_photon_events;
  parallel_items(static_cast<int>(chunks), threads, [&](int c) {
    Random rng(scene.gi.seed, static_cast<std::uint32_t>(map), static_cast<std::uint64_t>(c));
    const std::int64_t n = std::min(kChunk, count - c * kChunk);
    std::vector<Photon>& out = parts[static_cast<std::size_t>(c)];
    std::vector<Photon>& vol = volume_parts[static_cast<std::size_t>(c)];
    for (std::int64_t i = 0; i < n; ++i) {
      if (i % kCancelEvery == kCancelEvery - 1) check_cancel();
      const std::size_t before = out.size() + vol.size();
      trace_one(scene, surfaces, lights, count, map, global_skips_caustics, rng, &out, &vol);
      const auto added = static_cast<std::int64_t>(out.size() + vol.size() - before);
      if (added > 0 && stored->fetch_add(added) + added > cap) {
        throw PhotonEventLimit(cap, c * kChunk + i + 1);
      }
    }
  });
  if (volume) *volume = concatenate(volume_parts);
  return concatenate(parts);
}

}  // namespace

bool has_specular(const Scene& scene) {
  return std::any_of(scene.occluders.begin(), scene.occluders.end(), [](const Occluder& o) {
    return o.material.type != MaterialType::kDiffuse;
  });
}

PhotonMaps trace_photons(const Scene& scene, const GiScene& surfaces,
                         const PhotonTraceOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  PhotonMaps maps;
  if (scene.lights.empty()) return maps;
  int threads = options.threads > 0 ? options.threads
                                    : static_cast<int>(std::thread::hardware_concurrency());
  threads = std::max(1, threads);
  const bool caustics = has_specular(scene) && scene.gi.caustic_photons > 0;
  std::atomic<std::int64_t> stored{0};  // events of both maps, against gi.max_photon_events
  maps.emitted_global = scene.gi.photons;
  if (maps.emitted_global > 0) {
    maps.global = trace_map(scene, surfaces, maps.emitted_global, MapKind::kGlobal, caustics,
                            threads, &maps.volume, &stored);
  }
  if (caustics) {
    maps.emitted_caustic = scene.gi.caustic_photons;
    maps.caustic = trace_map(scene, surfaces, maps.emitted_caustic, MapKind::kCaustic, true,
                             threads, nullptr, &stored);
  }
  maps.trace_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return maps;
}


double default_volume_radius(const Scene& scene, std::int64_t volume_photons) {
  const Aabb box = scene_box(scene);
  if (box.empty() || volume_photons <= 0) return 1.0;
  const Vec3 s = box.hi - box.lo;
  // A flat box (the lights and a floor only) still holds a layer of fog:
  // each side at least a tenth of the largest.
  const double m = 0.1 * std::max({s[0], s[1], s[2]});
  const double volume = std::max(s[0], m) * std::max(s[1], m) * std::max(s[2], m);
  if (!(volume > 0.0)) return 1.0;
  constexpr double kPerKernel = 50.0;
  return std::cbrt(3.0 * kPerKernel * volume /
                   (4.0 * std::numbers::pi * static_cast<double>(volume_photons)));
}

namespace {

// The radius that puts k photons in pi r^2 of the scene box's surface area
// spread over `photons`, k = k0 at 1e5 and growing as photons^(2/3): r ~
// photons^(-1/6), the radius that balances a density estimate's bias
// (~ r^2) against its noise (~ 1 / sqrt(N r^2)), so the error falls as
// photons^(-1/3). A fixed k would keep the noise fixed.
double radius_for(const Scene& scene, std::int64_t photons, double k0) {
  const Aabb box = scene_box(scene);
  if (box.empty() || photons <= 0) return 1.0;
  const Vec3 s = box.hi - box.lo;
  const double area = 2.0 * (s[0] * s[1] + s[1] * s[2] + s[2] * s[0]);
  if (!(area > 0.0)) return 1.0;
  const double n = static_cast<double>(photons);
  const double k = k0 * std::cbrt((n / 1e5) * (n / 1e5));
  return std::sqrt(k * area / (std::numbers::pi * n));
}

}  // namespace

double default_photon_radius(const Scene& scene, std::int64_t photons) {
  // k0 = 50 where photons carry direct light (sharp: shadows, the light's
  // falloff); 800 (four times the radius) where they carry only the later
  // bounces, which vary slowly: on the Cornell box at 1e5 photons that
  // radius keeps every wall within 5% of the reference, the radius half as
  // large (k0 200, the default before 2026-11-26) left the floor and the
  // red wall at 5.7% and 5.4% (docs/gi.md).
  return radius_for(scene, photons,
                    scene.gi.direct == DirectLightMethod::kShadowMaps ? 800.0 : 50.0);
}

double default_caustic_radius(const Scene& scene, std::int64_t caustic_photons) {
  // Caustics are sharp whoever carries direct light: k0 200 with the direct
  // pass (as before 2026-11-26), 50 without.
  return kCausticRadiusScale *
         radius_for(scene, std::max<std::int64_t>(caustic_photons, 1),
                    scene.gi.direct == DirectLightMethod::kShadowMaps ? 200.0 : 50.0);
}

SplatRadii splat_radii(const Scene& scene, double drawn) {
  const double share = display_share(drawn);
  auto count = [&](std::int64_t n) {
    return std::max<std::int64_t>(1, std::llround(share * static_cast<double>(n)));
  };
  return {scene.gi.radius > 0.0 ? scene.gi.radius : default_photon_radius(scene, count(scene.gi.photons)),
          scene.gi.caustic_radius > 0.0 ? scene.gi.caustic_radius
                                        : default_caustic_radius(scene, count(scene.gi.caustic_photons))};
}

}  // namespace beamcast
