// Light transport in a homogeneous medium on the CPU (issue 15, items 2 and
// 7): the volume photon map's power and free paths against closed forms, and
// the path tracer's single scattering against a quadrature of its integral.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <limits>
#include <random>

#include "gi/gi_scene.hpp"
#include "gi/path_tracer.hpp"
#include "gi/phase.hpp"
#include "gi/photon_map.hpp"
#include "render/quadrature.hpp"

namespace beamcast {
namespace {

constexpr double kPi = std::numbers::pi;

// A point light of flux `phi` at the origin in an infinite medium, nothing else.
Scene point_in_fog(double phi, double sigma_s, double sigma_a, double k) {
  Scene s;
  Light l;
  l.shape = PointLight{{0.0, 0.0, 0.0}};
  l.flux = {phi, phi, phi};
  s.lights.push_back(l);
  s.medium = Medium{.sigma_s = sigma_s, .sigma_a = sigma_a, .k = k};
  return s;
}

// Every photon meets the medium (nothing else is there); at each event it
// survives with the albedo L = sigma_s / sigma_t and is then stored, so over
// at most D events the stored power sums to phi (L + L^2 + ... + L^D); the
// first events lie at exponential distances of mean 1 / sigma_t.
// Tolerances: the event count per photon is geometric (mean 1, variance 2 at
// L = 1/2), so the stored power's relative standard error over N = 1e5
// photons is sqrt(2 / N) = 0.45%: 2% is 4.5 of them; the first events' mean
// distance over ~5e4 of them has standard error 0.45% too.
TEST(MediumTransport, VolumePhotonsCarryTheAlbedoSeries) {
  Scene scene = point_in_fog(3.0, 0.5, 0.5, 0.4);
  scene.gi.photons = 100000;
  scene.gi.caustic_photons = 0;
  const GiScene gi(scene);
  const PhotonMaps maps = trace_photons(scene, gi);
  EXPECT_TRUE(maps.global.empty());
  ASSERT_FALSE(maps.volume.empty());
  const double albedo = 0.5;
  const int depth = scene.gi.max_depth;
  const double want = 3.0 * albedo * (1.0 - std::pow(albedo, depth)) / (1.0 - albedo);
  double power = 0.0, first_distance = 0.0;
  int first = 0;
  for (const Photon& p : maps.volume) {
    power += p.power[0];
    if (p.bounces == 0) {
      first_distance += std::sqrt(p.p[0] * p.p[0] + p.p[1] * p.p[1] + p.p[2] * p.p[2]);
      ++first;
    }
  }
  EXPECT_NEAR(power / want, 1.0, 0.02);
  ASSERT_GT(first, 40000);
  EXPECT_NEAR(first_distance / first, 1.0 / scene.medium->sigma_t(), 0.02);
}

// A camera ray past a point light of intensity I = phi / (4 pi) at distance
// 1 from it, single scattering only (max_depth 1: the first event's
// next-event estimate): L = integral over t of
//   e^(-sigma_t t) sigma_s p(mu) I e^(-sigma_t d) / d^2,
// d the distance from the ray point to the light, mu = cos between the
// light's travel and the ray's reverse (gi/phase.hpp). 2e5 paths; the bound
// is 4 standard errors of their mean (measured from the samples).
TEST(MediumTransport, PathTracerSingleScatteringMatchesQuadrature) {
  const double phi = 4.0 * kPi, sigma_s = 0.2, sigma_a = 0.3, k = 0.5;
  const Scene scene = point_in_fog(phi, sigma_s, sigma_a, k);
  const GiScene gi(scene);
  const Vec3 o{-5.0, -1.0, 0.0}, v{1.0, 0.0, 0.0};
  const double st = sigma_s + sigma_a;
  auto integrand = [&](double t) {
    const Vec3 x = o + t * v;
    const Vec3 to_light = Vec3{0.0, 0.0, 0.0} - x;
    const double d = length(to_light);
    const double mu = dot((1.0 / d) * to_light, v);
    return std::exp(-st * t) * sigma_s * schlick_phase(k, mu) * (phi / (4.0 * kPi)) *
           std::exp(-st * d) / (d * d);
  };
  const double pts[] = {0.0, 3.0, 5.0, 7.0, 20.0, 80.0};
  quad::Options qo;
  qo.rel_tol = 1e-10;
  const double want = quad::integrate_pieces(integrand, pts, std::size(pts), qo).value;

  PathTraceOptions opts;
  opts.max_depth = 1;
  std::mt19937_64 rng(7);
  const int n = 200000;
  double s = 0.0, s2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double x = trace_radiance(gi, o, v, 0.0, std::numeric_limits<double>::infinity(), opts,
                                    rng)[0];
    s += x;
    s2 += x * x;
  }
  const double mean = s / n;
  const double se = std::sqrt(std::max(0.0, s2 / n - mean * mean) / n);
  EXPECT_NEAR(mean, want, 4.0 * se) << "want " << want << " got " << mean << " se " << se;
  EXPECT_LT(se, 0.02 * want);  // the test resolves 8% errors at least
}

}  // namespace
}  // namespace beamcast
