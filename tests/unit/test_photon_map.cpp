// Photon tracing (gi/photon_map.hpp) on scenes with closed-form answers:
// power conservation in a closed diffuse sphere, the footprint and power of
// a mirror's caustic, radial refraction through a glass sphere, and
// determinism across thread counts.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>

#include "gi/gi_scene.hpp"
#include "gi/photon_gather.hpp"
#include "gi/photon_map.hpp"
#include "protocol/scene_json.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

json camera() { return json::array({{{"position", {0, 0, 0.5}}, {"target", {0, 0, 0}}}}); }

// A closed diffuse sphere of radius 1 around a point light of power `power`.
json closed_sphere(double albedo, double power, std::int64_t photons) {
  return {{"occluders", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1.0},
                          {"albedo", {albedo, albedo, albedo}}}}},
          {"lights", {{{"type", "point"}, {"position", {0, 0, 0}}, {"power", power}}}},
          {"gi", {{"photons", photons}, {"caustic_photons", 0}}},
          {"cameras", camera()}};
}

double total_power(const std::vector<Photon>& photons, int channel) {
  double sum = 0.0;
  for (const Photon& p : photons) sum += p.power[channel];
  return sum;
}

TEST(PhotonMap, ClosedDiffuseSphereConservesPower) {
  constexpr double kAlbedo = 0.5, kPower = 3.0;
  constexpr std::int64_t kPhotons = 20000;
  const Scene scene = parse_scene(closed_sphere(kAlbedo, kPower, kPhotons), {});
  const GiScene surfaces(scene);
  const PhotonMaps maps = trace_photons(scene, surfaces);
  EXPECT_EQ(maps.emitted_global, kPhotons);
  EXPECT_TRUE(maps.caustic.empty());
  double direct = 0.0;
  std::int64_t direct_count = 0;
  for (const Photon& p : maps.global) {
    // Every photon lies on the wall and faces the centre.
    const double r = std::sqrt(p.p[0] * p.p[0] + p.p[1] * p.p[1] + p.p[2] * p.p[2]);
    ASSERT_NEAR(r, 1.0, 1e-5);  // float storage of a point at distance 1
    ASSERT_LT(p.n[0] * p.p[0] + p.n[1] * p.p[1] + p.n[2] * p.p[2], -0.999);
    if (p.bounces == 0) {
      direct += p.power[0];
      ++direct_count;
    }
  }
  // Every emitted photon hits the wall once straight from the light: exact
  // up to float rounding of the powers.
  EXPECT_EQ(direct_count, kPhotons);
  EXPECT_NEAR(direct, kPower, 1e-4 * kPower);
  // With Russian roulette at p = albedo each survivor keeps its power, and a
  // path stores at most max_depth (16) photons: expected total
  // Phi (1 - rho^16) / (1 - rho). The bounce count per path is geometric
  // (variance rho / (1 - rho)^2 = 2), so the relative standard deviation of
  // the total over 20 000 paths is sqrt(2 / 20000) / 2 = 0.5%; 2.5% is 5 sigma.
  const double expected = kPower * (1.0 - std::pow(kAlbedo, 16)) / (1.0 - kAlbedo);
  EXPECT_NEAR(total_power(maps.global, 0), expected, 0.025 * expected);
}

TEST(PhotonMap, MapsAreTheSameForAnyThreadCount) {
  const Scene scene = parse_scene(closed_sphere(0.7, 1.0, 10000), {});
  const GiScene surfaces(scene);
  const PhotonMaps one = trace_photons(scene, surfaces, {.threads = 1});
  const PhotonMaps three = trace_photons(scene, surfaces, {.threads = 3});
  ASSERT_EQ(one.global.size(), three.global.size());
  EXPECT_EQ(std::memcmp(one.global.data(), three.global.data(), one.global.size() * sizeof(Photon)), 0);
  json other = closed_sphere(0.7, 1.0, 10000);
  other["gi"]["seed"] = 2;
  const Scene reseeded = parse_scene(other, {});
  const GiScene surfaces2(reseeded);
  const PhotonMaps two = trace_photons(reseeded, surfaces2, {.threads = 1});
  EXPECT_FALSE(two.global.size() == one.global.size() &&
               std::memcmp(one.global.data(), two.global.data(), one.global.size() * sizeof(Photon)) == 0);
}

// A point light at height 0.5 between a diffuse floor (y = 0) and a square
// mirror of half-side 0.5 at y = 1 facing down. Reflected photons come from
// the light's mirror image at y = 1.5, so they land within |x|, |z| <= 1.5.
TEST(PhotonMap, MirrorCausticLandsInItsFootprintWithItsPower) {
  constexpr std::int64_t kPhotons = 100000;
  const json j = {
      {"occluders",
       {{{"type", "quad"}, {"corner", {-10, 0, -10}}, {"edge_u", {0, 0, 20}}, {"edge_v", {20, 0, 0}},
         {"sides", 1}, {"albedo", {0.5, 0.5, 0.5}}},
        {{"type", "quad"}, {"corner", {-0.5, 1, -0.5}}, {"edge_u", {1, 0, 0}}, {"edge_v", {0, 0, 1}},
         {"sides", 1}, {"material", {{"type", "mirror"}, {"reflectance", {0.8, 0.8, 0.8}}}}}}},
      {"lights", {{{"type", "point"}, {"position", {0, 0.5, 0}}, {"power", 1.0}}}},
      {"gi", {{"photons", 1000}, {"caustic_photons", kPhotons}}},
      {"cameras", camera()}};
  const Scene scene = parse_scene(j, {});
  const GiScene surfaces(scene);
  const PhotonMaps maps = trace_photons(scene, surfaces);
  ASSERT_FALSE(maps.caustic.empty());
  for (const Photon& p : maps.caustic) {
    ASSERT_EQ(p.bounces, 1);
    ASSERT_EQ(p.caustic, 1);
    ASSERT_NEAR(p.p[1], 0.0f, 1e-6);
    ASSERT_LE(std::abs(p.p[0]), 1.5 + 1e-5);
    ASSERT_LE(std::abs(p.p[2]), 1.5 + 1e-5);
  }
  for (const Photon& p : maps.global) ASSERT_EQ(p.caustic, 0) << "L S+ D paths belong to the caustic map";
  // The mirror covers 4 arcsin(1/2) = 2 pi / 3 sr of the light's 4 pi: 1/6 of
  // the flux, times its reflectance 0.8. The caustic photon count is binomial
  // (p = 0.133, n = 1e5): relative standard deviation 0.8%; 4% is 5 sigma.
  const double expected = 0.8 / 6.0;
  EXPECT_NEAR(total_power(maps.caustic, 1), expected, 0.04 * expected);
}

// A point light at the centre of a glass sphere (radius 0.5, ior 1.5) inside a
// black diffuse sphere of radius 1: every ray meets the glass at normal
// incidence, so refraction keeps it radial, and all the flux (tint 1, nothing
// absorbs) reaches the outer wall through L S+ D paths: the caustic map.
TEST(PhotonMap, GlassSphereRefractsRadiallyAndLosesNothing) {
  constexpr std::int64_t kPhotons = 20000;
  const json j = {
      {"occluders",
       {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1.0}, {"albedo", {0, 0, 0}}},
        {{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 0.5},
         {"material", {{"type", "glass"}, {"ior", 1.5}}}}}},
      {"lights", {{{"type", "point"}, {"position", {0, 0, 0}}, {"power", 2.0}}}},
      {"gi", {{"photons", 0}, {"caustic_photons", kPhotons}}},
      {"cameras", camera()}};
  const Scene scene = parse_scene(j, {});
  const GiScene surfaces(scene);
  const PhotonMaps maps = trace_photons(scene, surfaces);
  EXPECT_TRUE(maps.global.empty());
  // Paths end only after max_depth (16) specular bounces inside the glass,
  // each reflection having probability F = 0.04 at normal incidence: never
  // in practice (0.04^14).
  EXPECT_EQ(static_cast<std::int64_t>(maps.caustic.size()), kPhotons);
  for (const Photon& p : maps.caustic) {
    const double r = std::sqrt(p.p[0] * p.p[0] + p.p[1] * p.p[1] + p.p[2] * p.p[2]);
    ASSERT_NEAR(r, 1.0, 1e-5);
    const double radial = (p.dir[0] * p.p[0] + p.dir[1] * p.p[1] + p.dir[2] * p.p[2]) / r;
    ASSERT_GT(radial, 0.9999) << "refraction at normal incidence bent the photon";
  }
  // Each photon carries flux / emitted: the sum is the power exactly (float rounding).
  EXPECT_NEAR(total_power(maps.caustic, 2), 2.0, 1e-4);
}

// The CPU estimators on the closed sphere, whose radiance is
// rho phi / (4 pi^2 (1 - rho)) everywhere on the wall (see
// ClosedDiffuseSphereConservesPower's scene).
TEST(PhotonMap, GatherEstimatesMatchTheClosedSphere) {
  constexpr double kRho = 0.5, kPhi = 10.0;
  const Scene scene = parse_scene(closed_sphere(kRho, kPhi, 200000), {});
  const GiScene surfaces(scene);
  const PhotonMaps maps = trace_photons(scene, surfaces);
  const PhotonGather gather(maps);
  const double expected = kRho * kPhi / (4.0 * std::numbers::pi * std::numbers::pi * (1.0 - kRho));
  // 64 wall points, the mean over them: each estimate holds ~1000 photons
  // (radius 0.1: pi r^2 / 4 pi = 1/400 of the ~400 000 stored), so its
  // relative standard deviation is about 3% and the mean's about 0.4%; the
  // chord-r cap has area exactly pi r^2 (no bias); 2% is 5 sigma.
  for (SplatKernel kernel : {SplatKernel::kBox, SplatKernel::kCone, SplatKernel::kEpanechnikov}) {
    double sum = 0.0, knn = 0.0;
    for (int i = 0; i < 64; ++i) {
      const double z = -1.0 + (i + 0.5) / 32.0, phi = 2.39996 * i;  // spiral over the sphere
      const double s = std::sqrt(1.0 - z * z);
      const Vec3 x{s * std::cos(phi), s * std::sin(phi), z};
      const Vec3 n = -1.0 * x;  // facing the centre
      sum += gather.fixed_radius(x, n, {kRho, kRho, kRho}, SplatRadii{0.1, 0.1}, kernel)[0];
      // k = 400 photons: r_k is biased low by about 1/(2k) in area for a
      // smooth density; the same 2% holds.
      knn += gather.nearest(x, n, {kRho, kRho, kRho}, 400)[0];
    }
    EXPECT_NEAR(sum / 64.0, expected, 0.02 * expected) << static_cast<int>(kernel);
    EXPECT_NEAR(knn / 64.0, expected, 0.02 * expected);
  }
}

TEST(PhotonMap, KernelsAreNormalizedOverTheDisk) {
  for (SplatKernel kernel : {SplatKernel::kBox, SplatKernel::kCone, SplatKernel::kEpanechnikov}) {
    // Midpoint rule in rings: integral of w(d) 2 pi d dd over [0, r].
    const double r = 0.7;
    const int n = 100000;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      const double d = (i + 0.5) * r / n;
      sum += splat_kernel(kernel, d, r) * 2.0 * std::numbers::pi * d * r / n;
    }
    EXPECT_NEAR(sum, 1.0, 1e-8);
    EXPECT_EQ(splat_kernel(kernel, r, r), 0.0);
  }
}

TEST(PhotonMap, DefaultRadiusFollowsTheSceneAndPhotonCount) {
  Scene scene = parse_scene(closed_sphere(0.5, 1.0, 1000), {});
  // Bounding box 2 x 2 x 2: area 24; 800 photons per pi r^2 at 1e5 photons
  // with the direct pass, 50 where photons carry direct light too.
  EXPECT_NEAR(default_photon_radius(scene, 100000), std::sqrt(800.0 * 24.0 / (std::numbers::pi * 1e5)),
              1e-12);
  scene.gi.direct = DirectLightMethod::kPhotons;
  EXPECT_NEAR(default_photon_radius(scene, 100000), std::sqrt(50.0 * 24.0 / (std::numbers::pi * 1e5)),
              1e-12);
  // 64 x the photons: r / 2 (photons^(-1/6)), so 16 x the photons per disk.
  EXPECT_NEAR(default_photon_radius(scene, 6400000), 0.5 * default_photon_radius(scene, 100000), 1e-12);
}

}  // namespace
}  // namespace beamcast
