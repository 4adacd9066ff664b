// What the "specular" pass shows through mirrors and glass (gi/photon_gather.hpp,
// LitShading; issue 14, item 4) against closed forms: a quad light seen in a
// mirror and through a glass slab, deterministically (both branches of the
// glass followed, no sampling).
#include <gtest/gtest.h>

#include <numbers>

#include "gi/gi_scene.hpp"
#include "gi/photon_gather.hpp"
#include "gi/photon_map.hpp"

namespace beamcast {
namespace {

Occluder quad(const Vec3& corner, const Vec3& eu, const Vec3& ev, const Material& m) {
  Occluder o;
  o.shape = QuadOccluder{corner, eu, ev, true};
  o.albedo = {0.8, 0.8, 0.8};
  o.material = m;
  return o;
}

// A quad light of radiance L (flux = pi A L, as the parser makes it).
Light quad_light(const Vec3& corner, const Vec3& eu, const Vec3& ev, const Color& L) {
  QuadLight q;
  q.corner = corner;
  q.edge_u = eu;
  q.edge_v = ev;
  const Vec3 n = cross(eu, ev);
  q.area = length(n);
  q.normal = (1.0 / q.area) * n;
  Light l;
  l.shape = q;
  l.flux = (std::numbers::pi * q.area) * L;
  return l;
}

TEST(LitShading, AMirrorShowsTheLightTimesItsReflectance) {
  Scene scene;
  const Color L{2.0, 3.0, 4.0};
  Material mirror;
  mirror.type = MaterialType::kMirror;
  mirror.reflectance = {0.9, 0.5, 0.2};
  // Mirror floor y = 0 facing up; the ray from (-2, 2, 0) to the origin
  // reflects along (1, 1, 0) into the light centred at (2, 2, 0) facing back.
  scene.occluders.push_back(quad({-10.0, 0.0, -10.0}, {0.0, 0.0, 20.0}, {20.0, 0.0, 0.0}, mirror));
  scene.lights.push_back(quad_light({1.5, 2.5, -1.0}, {1.0, -1.0, 0.0}, {0.0, 0.0, 2.0}, L));
  const GiScene gi(scene);
  const PhotonGather gather(PhotonMaps{});
  const LitShading shading(scene, gi, gather);
  const Color c = shading.trace({-2.0, 2.0, 0.0}, normalize(Vec3{1.0, -1.0, 0.0}), 0.0, 1e9);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], mirror.reflectance[k] * L[k], 1e-12 * L[k]);
}

TEST(LitShading, AGlassSlabTransmitsTheFresnelSeries) {
  Scene scene;
  const Color L{4.0, 4.0, 4.0};
  Material glass;
  glass.type = MaterialType::kGlass;
  glass.ior = 1.5;
  glass.tint = {0.9, 0.8, 0.7};
  // A slab z in [1, 1.1] between the ray's origin (z = 5) and the light
  // (z = 0), each face's normal pointing out of the glass.
  scene.occluders.push_back(quad({-5.0, -5.0, 1.1}, {10.0, 0.0, 0.0}, {0.0, 10.0, 0.0}, glass));
  scene.occluders.push_back(quad({-5.0, -5.0, 1.0}, {0.0, 10.0, 0.0}, {10.0, 0.0, 0.0}, glass));
  scene.lights.push_back(quad_light({-2.0, -2.0, 0.0}, {4.0, 0.0, 0.0}, {0.0, 4.0, 0.0}, L));
  const GiScene gi(scene);
  const PhotonGather gather(PhotonMaps{});
  const LitShading shading(scene, gi, gather);
  const Color c = shading.trace({0.0, 0.0, 5.0}, {0.0, 0.0, -1.0}, 0.0, 1e9);
  // Normal incidence: F = ((n - 1) / (n + 1))^2 = 0.04 at each face. Through
  // in, 2k inner reflections, out: (1 - F)^2 F^2k, the tint once per
  // crossing (twice); the branch weight cut-off (1e-3) ends the series
  // after k = 1, so the next term (F^4 = 2.6e-6 of the first) is missing:
  // 1e-5 relative.
  const double F = 0.04;
  for (int k = 0; k < 3; ++k) {
    const double t2 = glass.tint[k] * glass.tint[k];
    const double expected = L[k] * (1.0 - F) * (1.0 - F) * t2 * (1.0 + F * F);
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
  scene.occluders.push_back(quad({2.0, -1.0, -10.0}, {0.0, 20.0, 0.0}, {0.0, 0.0, 20.0}, Material{}));
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

}  // namespace
}  // namespace beamcast
