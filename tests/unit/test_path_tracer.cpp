// The path-traced reference (gi/path_tracer.hpp) against closed forms: a
// furnace (diffuse sphere lit from its centre), a quad light seen directly,
// in a mirror and through a glass slab; and its determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "gi/gi_scene.hpp"
#include "gi/path_tracer.hpp"
#include "protocol/camera.hpp"
#include "protocol/density.hpp"
#include "render/reference.hpp"
#include "tests/common/lit_shapes.hpp"

namespace beamcast {
namespace {

constexpr double kPi = std::numbers::pi;

using test::make_camera;

using test::quad_light;
using test::quad_occluder;

struct Stats {
  double mean = 0.0;
  double se = 0.0;  // standard error of the mean over pixels
};

// Mean and standard error of channel k over the pixels: every pixel is an
// independent estimate (its own generator) of the same value in these scenes.
Stats pixel_stats(const std::vector<Color>& img, int k) {
  double s = 0.0, s2 = 0.0;
  for (const Color& c : img) {
    s += c[k];
    s2 += c[k] * c[k];
  }
  const double n = static_cast<double>(img.size());
  const double mean = s / n;
  const double var = std::max(0.0, (s2 - n * mean * mean) / (n - 1.0));
  return {mean, std::sqrt(var / n)};
}

// A closed diffuse sphere of radius R with a point light of flux Phi at its
// centre. Every wall point gets the direct irradiance E = Phi / (4 pi R^2),
// and the form factor from any point of a sphere's inside to an element dA of
// it is dA / (4 pi R^2), so the radiosity B is uniform: B = rho (E + B), and
// the radiance is L = B / pi = rho Phi / (4 pi^2 R^2 (1 - rho)).
Scene furnace(double rho, double R, double phi) {
  Scene s;
  Occluder o;
  o.shape = SphereOccluder{{0.0, 0.0, 0.0}, R};
  o.albedo = {rho, rho, rho};
  s.occluders.push_back(o);
  Light l;
  l.shape = PointLight{{0.0, 0.0, 0.0}};
  l.flux = {phi, phi, phi};
  s.lights.push_back(l);
  return s;
}

double furnace_radiance(double rho, double R, double phi) {
  return rho * phi / (4.0 * kPi * kPi * R * R * (1.0 - rho));
}

TEST(PathTracer, FurnaceMatchesClosedForm) {
  const double R = 1.0, phi = 10.0;
  // The camera inside, off centre, sees only wall.
  const Camera cam = make_camera({0.0, 0.2, 0.3}, {0.5, 0.0, 1.0}, 60.0, 64, 64);
  for (const double rho : {0.5, 0.8}) {
    const Scene scene = furnace(rho, R, phi);
    const GiScene gi(scene);
    PathTraceOptions po;
    po.spp = 64;
    po.max_depth = 100000;  // Russian roulette ends the paths; no truncation bias
    const std::vector<Color> img = path_trace(gi, cam, po);
    const double expected = furnace_radiance(rho, R, phi);
    const Stats st = pixel_stats(img, 0);
    const double rel_err = st.mean / expected - 1.0;
    const double rel_se = st.se / expected;
    std::printf("furnace rho %.1f: L %.6f expected %.6f rel err %+.4f%% (standard error %.4f%%)\n",
                rho, st.mean, expected, 100.0 * rel_err, 100.0 * rel_se);
    // The 1% bound of issue 14 is meaningful only if it is several standard
    // errors wide: 64x64 pixels x 64 paths give 0.08% (rho 0.5) and 0.16%
    // (rho 0.8), measured from the pixels' own spread, so 1% is >= 5 standard
    // errors (a correct tracer fails it with probability < 1e-6) while a
    // missing term (at rho 0.8 the first bounce alone is 16% of L) fails it by
    // far. The second check asks the same at 5 of this run's standard errors.
    EXPECT_LT(rel_se, 0.002) << rho;
    EXPECT_LT(std::abs(rel_err), 0.01) << rho;
    EXPECT_LT(std::abs(rel_err), 5.0 * rel_se) << rho;
    // Grey in, grey out: the channels use the same paths.
    for (const Color& c : img) {
      ASSERT_EQ(c[0], c[1]);
      ASSERT_EQ(c[0], c[2]);
    }
  }
}

TEST(PathTracer, FurnaceDirectOnlyIsExact) {
  // One interaction: only next-event estimation at the first hit, which is
  // exact for a point light (no random choice reaches the value), so every
  // pixel is rho Phi / (4 pi^2 R^2) up to rounding; rho = 0 gives black.
  const double R = 2.5, phi = 7.0;
  const Camera cam = make_camera({0.3, -0.4, 0.1}, {1.0, 1.0, 1.0}, 70.0, 16, 12);
  for (const double rho : {0.0, 0.3, 0.8}) {
    const Scene scene = furnace(rho, R, phi);
    const GiScene gi(scene);
    PathTraceOptions po;
    po.spp = 4;
    po.max_depth = 1;
    const double expected = rho * phi / (4.0 * kPi * kPi * R * R);
    for (const Color& c : path_trace(gi, cam, po)) {
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(c[k], expected, 1e-12 * phi) << rho;
    }
  }
}

TEST(PathTracer, QuadLightSeenDirectlyGivesItsRadiance) {
  Scene scene;
  const Color L{17.0, 12.0, 4.0};
  scene.lights.push_back(quad_light({-2.0, -2.0, 0.0}, {4.0, 0.0, 0.0}, {0.0, 4.0, 0.0}, L));
  const GiScene gi(scene);
  const Camera cam = make_camera({0.3, 0.1, 3.0}, {0.0, 0.0, 0.0}, 10.0, 8, 8);
  for (const Color& c : path_trace(gi, cam, PathTraceOptions{.spp = 4})) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], L[k], 1e-12 * L[k]);
  }
  // From behind it is not seen (one-sided) and the background shows.
  scene.background = {0.1, 0.2, 0.3};
  const GiScene gi_back(scene);
  const Camera back = make_camera({0.0, 0.0, -3.0}, {0.0, 0.0, 0.0}, 10.0, 4, 4);
  for (const Color& c : path_trace(gi_back, back, PathTraceOptions{.spp = 2})) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(c[k], scene.background[k]);
  }
}

TEST(PathTracer, MirrorReflectsTheLightTimesReflectance) {
  const Color L{5.0, 3.0, 2.0}, reflectance{0.9, 0.5, 0.2};
  // The camera at (-2, 2, 0) looks at the origin: the reflected rays reach the light.
  const Scene scene = test::mirror_floor_and_light(L, reflectance);
  const GiScene gi(scene);
  const Camera cam = make_camera({-2.0, 2.0, 0.0}, {0.0, 0.0, 0.0}, 4.0, 8, 8);
  for (const Color& c : path_trace(gi, cam, PathTraceOptions{.spp = 4})) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], reflectance[k] * L[k], 1e-12 * L[k]);
  }
}

TEST(PathTracer, GlassSlabTransmitsTheFresnelSeries) {
  const Color L{4.0, 4.0, 4.0}, tint{0.9, 0.8, 0.7};
  // The slab between the camera (z = 5) and the light (z = 0).
  const Scene scene = test::glass_slab_over_light(L, tint);
  const GiScene gi(scene);
  const Camera cam = make_camera({0.0, 0.0, 5.0}, {0.0, 0.0, 0.0}, 2.0, 48, 48);
  PathTraceOptions po;
  po.spp = 32;
  po.max_depth = 1000;
  const std::vector<Color> img = path_trace(gi, cam, po);
  // Normal incidence: F = ((n - 1) / (n + 1))^2 = 0.04 at each face (within
  // 1e-6 over the 2-degree view). Paths through: in, 2k inner reflections,
  // out: sum_k (1 - F)^2 F^(2k) = (1 - F)^2 / (1 - F^2) = (1 - F) / (1 + F),
  // with the tint twice (one per crossing); reflected paths leave to the
  // black background.
  const double F = 0.04;
  for (int k = 0; k < 3; ++k) {
    const double expected = L[k] * tint[k] * tint[k] * (1.0 - F) / (1.0 + F);
    const Stats st = pixel_stats(img, k);
    std::printf("glass slab channel %d: %.6f expected %.6f (%+.3f%%, standard error %.3f%%)\n", k,
                st.mean, expected, 100.0 * (st.mean / expected - 1.0), 100.0 * st.se / expected);
    // Each path either reaches the light or not (p = 0.92): about 0.1%
    // standard error with 73 728 paths; 5 standard errors.
    EXPECT_NEAR(st.mean, expected, 5.0 * st.se) << k;
    EXPECT_LT(st.se / expected, 0.002) << k;
  }
}

// A diffuse floor under a quad light, nothing else: every path after the
// first diffuse bounce leaves the scene or ends on the light, so the floor's
// radiance is the direct term alone, rho L F with F the view factor from the
// floor point to the light. Were the light counted both by next-event
// estimation and when a bounce hits it, the result would be about twice that.
// F from a point to a parallel a x b rectangle at height h above one of its
// corners: (1 / 2 pi) [X / sqrt(1 + X^2) atan(Y / sqrt(1 + X^2)) + (X <-> Y)],
// X = a / h, Y = b / h; under the centre, four such rectangles.
TEST(PathTracer, DiffuseFloorUnderQuadLightIsTheDirectTermOnly) {
  const double a = 1.0, b = 0.6, h = 0.8, rho = 0.6, L = 3.0;
  Scene scene;
  scene.occluders.push_back(
      quad_occluder({-20.0, 0.0, -20.0}, {0.0, 0.0, 40.0}, {40.0, 0.0, 0.0}, {}, {rho, rho, rho}));
  // Facing down: cross((a, 0, 0), (0, 0, b)) = (0, -ab, 0).
  scene.lights.push_back(quad_light({-a / 2, h, -b / 2}, {a, 0.0, 0.0}, {0.0, 0.0, b}, {L, L, L}));
  const GiScene gi(scene);
  // Looking at the point under the light's centre from beside it (the light
  // does not hide it); the pixels see a spot 0.02 wide, where F varies < 1e-4.
  const Camera cam = make_camera({2.0, 1.0, 0.3}, {0.0, 0.0, 0.0}, 0.5, 32, 32);
  PathTraceOptions po;
  po.spp = 64;
  const std::vector<Color> img = path_trace(gi, cam, po);
  const auto corner = [](double X, double Y) {
    const double sx = std::sqrt(1.0 + X * X), sy = std::sqrt(1.0 + Y * Y);
    return (X / sx * std::atan(Y / sx) + Y / sy * std::atan(X / sy)) / (2.0 * kPi);
  };
  const double F = 4.0 * corner(a / 2 / h, b / 2 / h);
  const double expected = rho * L * F;
  const Stats st = pixel_stats(img, 0);
  std::printf("floor under quad light: %.6f expected %.6f (%+.3f%%, standard error %.3f%%)\n",
              st.mean, expected, 100.0 * (st.mean / expected - 1.0), 100.0 * st.se / expected);
  EXPECT_LT(st.se / expected, 0.005);
  EXPECT_NEAR(st.mean, expected, 5.0 * st.se);
}

// A small closed room with every material: a diffuse box of quads, a quad
// light under the ceiling, a mirror and a glass sphere.
Scene material_room() {
  Scene s;
  const Color w{0.7, 0.7, 0.7};
  // Five walls facing in (normal = cross(edge_u, edge_v)); the front is open.
  s.occluders.push_back(quad_occluder({0, 0, 0}, {0, 0, 4}, {4, 0, 0}, {}, w));  // floor
  s.occluders.push_back(quad_occluder({0, 4, 0}, {4, 0, 0}, {0, 0, 4}, {}, w));  // ceiling
  s.occluders.push_back(quad_occluder({0, 0, 4}, {0, 4, 0}, {4, 0, 0}, {}, w));  // back
  s.occluders.push_back(quad_occluder({0, 0, 0}, {0, 4, 0}, {0, 0, 4}, {}, {0.6, 0.1, 0.1}));
  s.occluders.push_back(quad_occluder({4, 0, 0}, {0, 0, 4}, {0, 4, 0}, {}, {0.1, 0.6, 0.1}));
  Occluder mirror;
  mirror.shape = SphereOccluder{{1.2, 0.8, 2.5}, 0.8};
  mirror.material.type = MaterialType::kMirror;
  s.occluders.push_back(mirror);
  Occluder glass;
  glass.shape = SphereOccluder{{2.8, 0.8, 1.8}, 0.8};
  glass.material.type = MaterialType::kGlass;
  s.occluders.push_back(glass);
  s.lights.push_back(quad_light({1.5, 3.99, 1.5}, {1, 0, 0}, {0, 0, 1}, {10.0, 9.0, 8.0}));
  return s;
}

TEST(PathTracer, DeterministicForSeedAndThreadCount) {
  const Scene scene = material_room();
  const GiScene gi(scene);
  const Camera cam = make_camera({2.0, 2.0, -3.0}, {2.0, 2.0, 2.0}, 60.0, 24, 16);
  PathTraceOptions po;
  po.spp = 4;
  po.threads = 1;
  const std::vector<Color> one = path_trace(gi, cam, po);
  po.threads = 3;
  EXPECT_EQ(path_trace(gi, cam, po), one);
  po.threads = 2;
  EXPECT_EQ(path_trace(gi, cam, po), one);
  po.seed = 2;
  const std::vector<Color> other = path_trace(gi, cam, po);
  EXPECT_NE(other, one);
  // A different seed is a different estimate of the same picture.
  double a = 0.0, b = 0.0;
  for (std::size_t i = 0; i < one.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_TRUE(std::isfinite(one[i][k]));
      ASSERT_GE(one[i][k], 0.0);
      a += one[i][k];
      b += other[i][k];
    }
  }
  EXPECT_GT(a, 0.0);
  EXPECT_NEAR(a / b, 1.0, 0.1);
}

TEST(PathTracer, ReferenceAddsBeamsUpToTheLitSurface) {
  // render_reference on a scene with lights: the path-traced radiance (here a
  // quad light seen directly, exact) plus the beams in front of it; a beam
  // behind the light is hidden.
  Scene scene;
  const Color L{2.0, 1.0, 0.5};
  scene.lights.push_back(quad_light({-2.0, -2.0, 0.0}, {4.0, 0.0, 0.0}, {0.0, 4.0, 0.0}, L));
  for (const double z : {1.5, -1.0}) {
    Beam b;
    b.shape = SphereBeam{{0.0, 0.0, z}};
    b.radius = 0.6;
    b.color = {0.5, 1.0, 2.0};
    ASSERT_TRUE(density_from_name("linear", &b.density));
    scene.beams.push_back(b);
  }
  const Camera cam = make_camera({0.0, 0.0, 3.0}, {0.0, 0.0, 0.0}, 20.0, 12, 12);
  const HdrImage img = render_reference(scene, cam, ReferenceOptions{.gi_spp = 2});
  const CameraBasis basis = camera_basis(cam);
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      const Ray ray = camera_ray(cam, basis, x, cam.height - 1 - y);
      const double t_light = 3.0 / -ray.dir[2];
      const double e =
          beam_energy_reference(scene.beams[0], ray.origin, ray.dir, ray.t_min, t_light);
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(img.at(x, y)[k], L[k] + scene.beams[0].color[k] * e, 1e-5) << x << " " << y;
      }
    }
  }
}

}  // namespace
}  // namespace beamcast
