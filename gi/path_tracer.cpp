#include "gi/path_tracer.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <thread>
#include <variant>

#include "gi/optics.hpp"
#include "gi/parallel.hpp"
#include "gi/phase.hpp"
#include "protocol/camera.hpp"
#include "protocol/cancel.hpp"
#include "protocol/check.hpp"
#include "protocol/lights/sampling.hpp"

namespace beamcast {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

double luminance(const Color& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

// SplitMix64's finalizer: neighbouring pixel indices give unrelated seeds.
std::uint64_t mix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// Everything a path needs that does not change per path: the lights' pick
// probabilities for next-event estimation.
class Tracer {
 public:
  Tracer(const GiScene& gi, const PathTraceOptions& opts)
      : gi_(gi), opts_(opts), medium_(gi.scene().medium_field()) {
    const Scene& s = gi.scene();
    // One light per diffuse hit, picked in proportion to its flux luminance
    // (uniformly when every flux is black).
    double total = 0.0;
    for (const Light& l : s.lights) total += std::max(0.0, luminance(l.flux));
    for (const Light& l : s.lights) {
      const double w = total > 0.0 ? std::max(0.0, luminance(l.flux)) / total
                                   : 1.0 / static_cast<double>(s.lights.size());
      pick_.push_back(w);
    }
  }

  Color radiance(Vec3 o, Vec3 v, double t_min, double t_max, std::mt19937_64& rng) const {
    const Scene& scene = gi_.scene();
    const double eps = gi_.epsilon();
    Color L{0.0, 0.0, 0.0};
    Color beta{1.0, 1.0, 1.0};  // path throughput
    bool specular = true;       // camera ray or last bounce specular: emission and background count
    const MediumField& medium = medium_;
    for (int depth = 0; depth < opts_.max_depth; ++depth) {
      const std::optional<SurfaceHit> hit = gi_.intersect(o, v, t_min, t_max);
      if (!medium.empty()) {
        // Free flight from o (the eye for the camera ray: the medium lies
        // before the near plane too, but what scatters there is not seen),
        // sampled exactly against the local extinction (MediumField::
        // free_path). An event's weight is the albedo sigma_s / sigma_t
        // there; a surface reached first has weight 1.
        const double t_hit = std::min(hit ? hit->t : kInf, medium.last_exit(o, v));
        const double t = medium.free_path(o, v, t_hit, -std::log1p(-uniform(rng)));
        const bool event = t < t_hit;
        if (event) {
          if (t < t_min) break;
          const Vec3 x = o + t * v;
          // sigma_t(x) is 0 only where x rounds to just outside a region
          // (a measure-zero event at its boundary): absorbed there, as the
          // photon tracer does, rather than a NaN weight.
          const double sigma_t = medium.sigma_t(x);
          beta = (sigma_t > 0.0 ? medium.sigma_s(x) / sigma_t : 0.0) * beta;
          const double k = medium.k(x);
          L = L + mul(beta, in_scattered(x, v, k, rng));
          // The two numbers drawn one statement each (a call's arguments are
          // evaluated in an unspecified order: g++ and clang differed), in
          // the order g++ drew them, so that earlier references stay exact.
          const double u2 = uniform(rng);
          const double u1 = uniform(rng);
          v = schlick_sample_direction(k, v, u1, u2);
          specular = false;
          if (depth >= 2) {
            const double q = std::min(0.95, std::max({beta[0], beta[1], beta[2]}));
            if (!(uniform(rng) < q)) break;
            beta = (1.0 / q) * beta;
          }
          o = x;
          t_min = 0.0;
          t_max = kInf;
          continue;
        }
      }
      if (!hit) {
        if (specular) L = L + mul(beta, scene.background);
        break;
      }
      if (hit->light >= 0) {
        // After a diffuse bounce next-event estimation has already counted it.
        if (specular) {
          const Light& light = scene.lights[hit->light];
          const double scale =
              std::visit([](const auto& k) { return k.radiance_scale(); }, light.shape);
          L = L + scale * mul(beta, light.flux);
        }
        break;  // lights absorb
      }
      BEAMCAST_DCHECK(hit->occluder >= 0, "a surface hit is a light or an occluder");
      const Occluder& occ = scene.occluders[hit->occluder];
      const Vec3& n = hit->n;  // faces the incoming ray
      switch (occ.material.type) {
        case MaterialType::kDiffuse: {
          L = L + mul(beta, direct(hit->p, n, occ.albedo, rng));
          const double u2 = uniform(rng);  // drawn as above
          const double u1 = uniform(rng);
          v = cosine_hemisphere(n, u1, u2);
          // f cos / pdf = (albedo / pi) cos / (cos / pi) = albedo.
          beta = mul(beta, occ.albedo);
          specular = false;
          break;
        }
        case MaterialType::kMirror:
          v = reflect(v, n);
          beta = mul(beta, occ.material.reflectance);
          specular = true;
          break;
        case MaterialType::kGlass: {
          // Outside is vacuum; `entering` says which side of the surface the ray came from.
          const double eta_i = hit->entering ? 1.0 : occ.material.ior;
          const double eta_t = hit->entering ? occ.material.ior : 1.0;
          const double F = fresnel_dielectric(-dot(v, n), eta_i, eta_t);
          const std::optional<Vec3> t = F < 1.0 ? refract(v, n, eta_i, eta_t) : std::nullopt;
          if (!t || uniform(rng) < F) {
            v = reflect(v, n);  // chosen with probability F (1 past the critical angle): weight 1
          } else {
            // Refraction, probability 1 - F: weight 1 times the tint of this crossing.
            // Radiance's (eta_t / eta_i)^2 is left out: it cancels over a path that
            // starts and ends outside the glass (camera and lights are outside).
            v = normalize(*t);
            beta = mul(beta, occ.material.tint);
          }
          specular = true;
          break;
        }
      }
      // Russian roulette after 3 interactions; the survivors carry the lost weight.
      if (depth >= 2) {
        const double q = std::min(0.95, std::max({beta[0], beta[1], beta[2]}));
        if (!(uniform(rng) < q)) break;
        beta = (1.0 / q) * beta;
      }
      o = hit->p;
      t_min = eps;
      t_max = kInf;
    }
    return L;
  }

 private:
  // One light picked by pick_ and a point on it seen from x (the uniforms
  // drawn in one order for every caller); empty if the pick has no weight.
  struct LightPick {
    const Light* light = nullptr;
    double probability = 0.0;
    LightSample sample;
  };
  std::optional<LightPick> pick_light(const Vec3& x, std::mt19937_64& rng) const {
    if (pick_.empty()) return std::nullopt;
    const double u = uniform(rng);
    const LightRandom lu{uniform(rng), uniform(rng), uniform(rng), uniform(rng)};
    std::size_t i = 0;
    double acc = pick_[0];
    while (u >= acc && i + 1 < pick_.size()) acc += pick_[++i];
    if (!(pick_[i] > 0.0)) return std::nullopt;
    const Light& light = gi_.scene().lights[i];
    return LightPick{&light, pick_[i],
                     std::visit([&](const auto& k) { return k.sample(x, lu); }, light.shape)};
  }

  // Next-event estimation at a diffuse point x (normal n facing the viewer):
  // reflected radiance from one light sample, picked by pick_.
  Color direct(const Vec3& x, const Vec3& n, const Color& albedo, std::mt19937_64& rng) const {
    const std::optional<LightPick> p = pick_light(x, rng);
    if (!p) return {0.0, 0.0, 0.0};
    const LightSample& s = p->sample;
    const double cos_x = dot(n, s.dir);
    if (!(s.g > 0.0) || !(cos_x > 0.0)) return {0.0, 0.0, 0.0};
    const double eps = gi_.epsilon();
    if (gi_.occluded(x, s.dir, eps, s.dist - eps)) return {0.0, 0.0, 0.0};
    // E = flux g cos_x / pick (times the medium's transmittance); L_out = (albedo / pi) E.
    const double k =
        s.g * cos_x * transmittance(x, s.dir, s.dist) / (std::numbers::pi * p->probability);
    return k * mul(albedo, p->light->flux);
  }

  // Next-event estimation at a point x of the medium on a path travelling
  // along v: the radiance one light sample scatters into -v,
  // p(mu) flux g T / pick, mu = dot(s.dir, v) (the light travels along
  // -s.dir, then towards the eye along -v: gi/phase.hpp's convention).
  Color in_scattered(const Vec3& x, const Vec3& v, double phase_k, std::mt19937_64& rng) const {
    const std::optional<LightPick> p = pick_light(x, rng);
    if (!p) return {0.0, 0.0, 0.0};
    const LightSample& s = p->sample;
    if (!(s.g > 0.0)) return {0.0, 0.0, 0.0};
    if (gi_.occluded(x, s.dir, 0.0, s.dist - gi_.epsilon())) return {0.0, 0.0, 0.0};
    const double k = schlick_phase(phase_k, dot(s.dir, v)) * s.g * transmittance(x, s.dir, s.dist) /
                     p->probability;
    return k * p->light->flux;
  }

  // e^(-optical depth) of the scene's medium along x + t l, t in [0, d] (1 without one).
  double transmittance(const Vec3& x, const Vec3& l, double d) const {
    return medium_.empty() ? 1.0 : std::exp(-medium_.optical_depth(x, l, 0.0, d));
  }

  const GiScene& gi_;
  const PathTraceOptions& opts_;
  MediumField medium_;  // the scene's medium (empty without one)
  std::vector<double> pick_;
};

}  // namespace

Color trace_radiance(const GiScene& gi, const Vec3& o, const Vec3& v, double t_min, double t_max,
                     const PathTraceOptions& opts, std::mt19937_64& rng) {
  return Tracer(gi, opts).radiance(o, v, t_min, t_max, rng);
}

std::vector<Color> path_trace(const GiScene& gi, const Camera& cam, const PathTraceOptions& opts) {
  const int w = std::max(cam.width, 0), h = std::max(cam.height, 0);
  std::vector<Color> img(static_cast<std::size_t>(w) * h, Color{0.0, 0.0, 0.0});
  if (w == 0 || h == 0 || opts.spp <= 0) return img;
  const Tracer tracer(gi, opts);
  const CameraBasis basis = camera_basis(cam);
  const std::uint64_t seed_key = mix64(opts.seed);

  auto trace_row = [&](int y) {
    const int py = h - 1 - y;  // camera rows count from the bottom
    for (int x = 0; x < w; ++x) {
      check_cancel();  // a pixel is spp paths: a row can take long
      const std::size_t index = static_cast<std::size_t>(y) * w + x;
      std::mt19937_64 rng(mix64(seed_key ^ index));
      Color sum{0.0, 0.0, 0.0};
      for (int s = 0; s < opts.spp; ++s) {
        const double nx = 2.0 * (x + uniform(rng)) / w - 1.0;
        const double ny = 2.0 * (py + uniform(rng)) / h - 1.0;
        const Ray ray = camera_ray_ndc(cam, basis, nx, ny);
        sum = sum + tracer.radiance(ray.origin, ray.dir, ray.t_min, ray.t_max, rng);
      }
      img[index] = (1.0 / opts.spp) * sum;
    }
    if (opts.on_row) opts.on_row();
  };

  parallel_items(h, opts.threads, trace_row);
  return img;
}

}  // namespace beamcast
