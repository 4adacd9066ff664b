// What the "specular" pass shows through mirrors and glass (gi/photon_gather.hpp,
// LitShading; issue 14, item 4) against closed forms: a quad light seen in a
// mirror and through a glass slab, deterministically (both branches of the
// glass followed, no sampling).
#include <gtest/gtest.h>

#include <cmath>

#include "gi/gi_scene.hpp"
#include "gi/photon_gather.hpp"
#include "gi/photon_map.hpp"
#include "tests/common/lit_shapes.hpp"

namespace beamcast {
namespace {

Occluder quad(const Vec3& corner, const Vec3& eu, const Vec3& ev, const Material& m) {
  return test::quad_occluder(corner, eu, ev, m);
}

// What LitShading shows along o + t d in a scene without photons.
Color trace_in(const Scene& scene, const Vec3& o, const Vec3& d) {
  const GiScene gi(scene);
  const PhotonGather gather(PhotonMaps{});
  return LitShading(scene, gi, gather).trace(o, d, 0.0, 1e9);
}

TEST(LitShading, AMirrorShowsTheLightTimesItsReflectance) {
  const Color L{2.0, 3.0, 4.0}, reflectance{0.9, 0.5, 0.2};
  const Color c = trace_in(test::mirror_floor_and_light(L, reflectance), {-2.0, 2.0, 0.0},
                           normalize(Vec3{1.0, -1.0, 0.0}));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], reflectance[k] * L[k], 1e-12 * L[k]);
}

TEST(LitShading, AGlassSlabTransmitsTheFresnelSeries) {
  const Color L{4.0, 4.0, 4.0}, tint{0.9, 0.8, 0.7};
  const Color c = trace_in(test::glass_slab_over_light(L, tint), {0.0, 0.0, 5.0}, {0.0, 0.0, -1.0});
  // Normal incidence: F = ((n - 1) / (n + 1))^2 = 0.04 at each face. Through
  // in, 2k inner reflections, out: (1 - F)^2 F^2k, the tint once per
  // crossing (twice); the branch weight cut-off (1e-3) ends the series
  // after k = 1, so the next term (F^4 = 2.6e-6 of the first) is missing:
  // 1e-5 relative.
  const double F = 0.04;
  for (int k = 0; k < 3; ++k) {
    const double expected = L[k] * (1.0 - F) * (1.0 - F) * tint[k] * tint[k] * (1.0 + F * F);
    EXPECT_NEAR(c[k], expected, 1e-5 * expected) << k;
  }
}

// A diffuse wall seen in a mirror shows what the wall shows directly
// (the photon estimate), times the reflectance.
TEST(LitShading, ADiffuseWallInAMirrorLooksAsItDoesDirectly) {
  Scene scene;
  Material mirror;
  mirror.type = MaterialType::kMirror;
  mirror.reflectance = {0.5, 0.5, 0.5};
  scene.occluders.push_back(quad({-10.0, 0.0, -10.0}, {0.0, 0.0, 20.0}, {20.0, 0.0, 0.0}, mirror));
  // A diffuse wall x = 2 facing -x.
  scene.occluders.push_back(
      quad({2.0, -1.0, -10.0}, {0.0, 20.0, 0.0}, {0.0, 0.0, 20.0}, Material{}));
  PhotonMaps maps;
  for (int i = 0; i < 50; ++i) {
    Photon p{};
    p.p[0] = 2.0f;
    p.p[1] = 2.0f + 0.01f * static_cast<float>(i % 7);
    p.p[2] = 0.01f * static_cast<float>(i % 5);
    p.n[0] = -1.0f;
    p.dir[0] = 1.0f;
    p.power[0] = 0.01f;
    p.power[1] = 0.02f;
    p.power[2] = 0.03f;
    p.bounces = 1;
    maps.global.push_back(p);
  }
  scene.gi.direct = DirectLightMethod::kPhotons;
  scene.gi.radius = 0.5;
  const GiScene gi(scene);
  const PhotonGather gather(maps);
  const LitShading shading(scene, gi, gather);
  // Directly: from (0, 2, 0) along +x to (2, 2, 0). In the mirror: from
  // (0, 2, 0) along (1, -2, 0) to the floor at (1, 0, 0), then along
  // (1, 2, 0) to the same wall point.
  const Color direct = shading.trace({0.0, 2.0, 0.0}, {1.0, 0.0, 0.0}, 0.0, 1e9);
  const Color mirrored = shading.trace({0.0, 2.0, 0.0}, normalize(Vec3{1.0, -2.0, 0.0}), 0.0, 1e9);
  ASSERT_GT(direct[0], 0.0);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(mirrored[k], 0.5 * direct[k], 1e-9 * direct[k]) << k;
}

// In a medium (issue 15) the segment beyond the mirror is attenuated: the
// light in the mirror of AMirrorShowsTheLightTimesItsReflectance, times
// e^(-sigma_t d), d = the distance from the mirror point to the light's
// centre, sqrt(8) (the camera's own segment is the medium pass's, not
// LitShading's).
TEST(LitShading, BeyondAMirrorTheMediumAttenuates) {
  const Color L{1.0, 2.0, 3.0}, reflectance{0.9, 0.5, 0.25};
  Scene scene = test::mirror_floor_and_light(L, reflectance);
  const Vec3 o{-2.0, 2.0, 0.0}, d = normalize(Vec3{1.0, -1.0, 0.0});
  const Color clear = trace_in(scene, o, d);
  scene.medium = Medium{.sigma_a = 0.2};
  const Color fogged = trace_in(scene, o, d);
  const double t = std::exp(-0.2 * std::sqrt(8.0));
  for (int k = 0; k < 3; ++k) {
    ASSERT_GT(clear[k], 0.0);
    EXPECT_NEAR(fogged[k], t * clear[k], 1e-12 * clear[k]) << k;
  }
}

}  // namespace
}  // namespace beamcast
