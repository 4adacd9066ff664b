// The global-illumination part of the scene format (issue 14, item 1):
// lights, materials and gi settings parse to the model, and every bad field
// is refused with its JSON pointer.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "gi/photon_map.hpp"
#include "protocol/errors.hpp"
#include "protocol/scene_json.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

json lit(json lights, json extra = json::object()) {
  json j = {{"occluders", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1.0}}}},
            {"lights", std::move(lights)},
            {"cameras", {{{"position", {0, 0, 5}}, {"target", {0, 0, 0}}}}}};
  j.update(extra);
  return j;
}

ErrorInfo error_of(const json& j, const SceneLimits& limits = {}) {
  try {
    SceneLoadOptions o;
    o.limits = limits;
    parse_scene(j, o);
  } catch (const ProtocolError& e) {
    return e.info();
  }
  ADD_FAILURE() << "scene was accepted: " << j.dump();
  return {};
}

#define EXPECT_REJECTED(scene, want_code, want_path)       \
  do {                                                     \
    const ErrorInfo info_ = error_of(scene);               \
    EXPECT_EQ(info_.code, (want_code)) << info_.message;   \
    EXPECT_EQ(info_.path, (want_path)) << info_.message;   \
    EXPECT_FALSE(info_.message.empty());                   \
  } while (0)

TEST(Lights, EachKindParsesWithItsFlux) {
  const Scene s = parse_scene(
      lit({{{"type", "point"}, {"position", {0, 2, 0}}, {"power", 10}, {"color", {1, 0.5, 0}}},
           {{"type", "spot"}, {"position", {0, 2, 0}}, {"direction", {0, -2, 0}}, {"inner_deg", 10},
            {"outer_deg", 40}},
           {{"type", "quad"}, {"corner", {0, 3, 0}}, {"edge_u", {2, 0, 0}}, {"edge_v", {0, 0, 0.5}},
            {"radiance", {17, 12, 4}}}}),
      {});
  ASSERT_EQ(s.lights.size(), 3u);
  EXPECT_TRUE(s.has_gi());
  EXPECT_EQ(s.lights[0].flux, (Color{10, 5, 0}));
  const auto& spot = std::get<SpotLight>(s.lights[1].shape);
  EXPECT_DOUBLE_EQ(spot.direction[1], -1.0);  // normalized
  EXPECT_NEAR(spot.cos_outer, std::cos(40.0 * std::numbers::pi / 180.0), 1e-15);
  // A quad of area 1 with radiance L emits pi L.
  const auto& quad = std::get<QuadLight>(s.lights[2].shape);
  EXPECT_NEAR(quad.area, 1.0, 1e-15);
  EXPECT_NEAR(s.lights[2].flux[0], 17 * std::numbers::pi, 1e-12);
  EXPECT_NEAR(quad.radiance_scale() * s.lights[2].flux[1], 12.0, 1e-12);
  // cross(edge_u, edge_v) = (2,0,0) x (0,0,0.5) = (0,-1,0): faces down.
  EXPECT_NEAR(quad.normal[1], -1.0, 1e-15);
}

TEST(Lights, SpotFalloffIntegratesToItsFlux) {
  const Scene s = parse_scene(lit({{{"type", "spot"}, {"position", {0, 0, 0}}, {"direction", {0, 0, 1}},
                                    {"inner_deg", 15}, {"outer_deg", 50}}}),
                              {});
  const auto& spot = std::get<SpotLight>(s.lights[0].shape);
  // Midpoint rule over cos(angle) in [-1, 1]: 2 pi * integral of the falloff.
  const int n = 200000;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += spot.falloff(-1.0 + (i + 0.5) * 2.0 / n);
  EXPECT_NEAR(2.0 * std::numbers::pi * sum * 2.0 / n, spot.solid_angle_weight, 1e-6);
}

TEST(Lights, MaterialsAndGiSettingsParse) {
  json j = lit({{{"type", "point"}, {"position", {0, 2, 0}}}},
               {{"gi", {{"photons", 5000}, {"caustic_photons", 7}, {"radius", 0.25}, {"kernel", "box"},
                        {"seed", 9}, {"max_depth", 3}, {"caustic_radius", 0.05}}}});
  j["occluders"].push_back({{"type", "sphere"}, {"center", {3, 0, 0}}, {"radius", 1.0},
                            {"material", {{"type", "glass"}, {"ior", 1.33}, {"tint", {1, 0.9, 0.8}}}}});
  j["occluders"].push_back({{"type", "sphere"}, {"center", {-3, 0, 0}}, {"radius", 1.0},
                            {"material", {{"type", "mirror"}, {"reflectance", {0.9, 0.9, 0.9}}}}});
  j["occluders"].push_back({{"type", "sphere"}, {"center", {0, 3, 0}}, {"radius", 1.0},
                            {"material", {{"type", "diffuse"}, {"albedo", {0.1, 0.2, 0.3}}}}});
  const Scene s = parse_scene(j, {});
  EXPECT_EQ(s.occluders[0].material.type, MaterialType::kDiffuse);
  EXPECT_EQ(s.occluders[1].material.type, MaterialType::kGlass);
  EXPECT_DOUBLE_EQ(s.occluders[1].material.ior, 1.33);
  EXPECT_EQ(s.occluders[2].material.type, MaterialType::kMirror);
  EXPECT_EQ(s.occluders[3].albedo, (Color{0.1, 0.2, 0.3}));
  EXPECT_EQ(s.gi.photons, 5000);
  EXPECT_EQ(s.gi.caustic_photons, 7);
  EXPECT_EQ(s.gi.kernel, SplatKernel::kBox);
  EXPECT_EQ(s.gi.seed, 9u);
  EXPECT_EQ(s.gi.max_depth, 3);
  EXPECT_DOUBLE_EQ(s.gi.caustic_radius, 0.05);
  // The caustic map's own radius; 0 takes a quarter of the default rule at
  // the caustic photon count.
  EXPECT_DOUBLE_EQ(splat_radii(s).caustic, 0.05);
  EXPECT_DOUBLE_EQ(splat_radii(s).global, 0.25);
  json d = lit({{{"type", "point"}, {"position", {0, 2, 0}}}}, {{"gi", {{"caustic_photons", 5000}}}});
  const Scene s0 = parse_scene(d, {});
  EXPECT_DOUBLE_EQ(splat_radii(s0).caustic, default_caustic_radius(s0, 5000));
  // With the direct pass the caustic rule holds 200 photons a disk, the
  // global one 800: half the radius at the same count.
  EXPECT_DOUBLE_EQ(default_caustic_radius(s0, 5000),
                   kCausticRadiusScale * 0.5 * default_photon_radius(s0, 5000));
  // A share of the maps drawn: the radii at the drawn counts (larger).
  EXPECT_DOUBLE_EQ(splat_radii(s0, 0.1).caustic, default_caustic_radius(s0, 500));
  EXPECT_GT(splat_radii(s0, 0.1).global, splat_radii(s0).global);
}

TEST(Lights, WithoutLightsTheSceneHasNoGi) {
  json j = lit(json::array());
  EXPECT_FALSE(parse_scene(j, {}).has_gi());
}

TEST(Lights, BadFieldsAreRefusedWithTheirPath) {
  EXPECT_REJECTED(lit({{{"type", "point"}, {"position", {0, 2, 0}}, {"power", -1}}}), "out_of_range",
                  "/lights/0/power");
  EXPECT_REJECTED(lit({{{"type", "laser"}, {"position", {0, 2, 0}}}}), "invalid_value", "/lights/0/type");
  EXPECT_REJECTED(lit({{{"type", "point"}}}), "missing_field", "/lights/0/position");
  EXPECT_REJECTED(lit({{{"type", "point"}, {"position", {0, 2, 0}}, {"direction", {0, 1, 0}}}}),
                  "unknown_field", "/lights/0/direction");
  EXPECT_REJECTED(lit({{{"type", "spot"}, {"position", {0, 2, 0}}, {"direction", {0, 0, 0}}}}),
                  "invalid_value", "/lights/0/direction");
  EXPECT_REJECTED(lit({{{"type", "spot"}, {"position", {0, 2, 0}}, {"direction", {0, 1, 0}},
                        {"inner_deg", 50}, {"outer_deg", 40}}}),
                  "out_of_range", "/lights/0/inner_deg");
  EXPECT_REJECTED(lit({{{"type", "quad"}, {"corner", {0, 3, 0}}, {"edge_u", {1, 0, 0}},
                        {"edge_v", {2, 0, 0}}}}),
                  "invalid_value", "/lights/0/edge_v");
  EXPECT_REJECTED(lit({{{"type", "quad"}, {"corner", {0, 3, 0}}, {"edge_u", {1, 0, 0}},
                        {"edge_v", {0, 0, 1}}, {"radiance", {1, 1, 1}}, {"power", 3}}}),
                  "invalid_value", "/lights/0/radiance");
  EXPECT_REJECTED(lit({{{"type", "point"}, {"position", {0, 2, 0}}, {"radiance", {1, 1, 1}}}}),
                  "unknown_field", "/lights/0/radiance");
  EXPECT_REJECTED(lit({{{"type", "point"}, {"position", {0, 2, 0}}}}, {{"gi", {{"caustic_radius", -0.1}}}}),
                  "out_of_range", "/gi/caustic_radius");
  EXPECT_REJECTED(lit({{{"type", "point"}, {"position", {0, 2, 0}}}}, {{"gi", {{"caustic_radius", "big"}}}}),
                  "wrong_type", "/gi/caustic_radius");
  EXPECT_REJECTED(lit({{{"type", "point"}, {"position", {0, 2, 0}}}}, {{"gi", {{"cluster", 1.5}}}}),
                  "out_of_range", "/gi/cluster");
  EXPECT_REJECTED(lit({{{"type", "point"}, {"position", {0, 2, 0}}}}, {{"gi", {{"cluster", -0.1}}}}),
                  "out_of_range", "/gi/cluster");
  // The interleave is 1 or 4 (a 2 x 2 pattern), nothing between; 2^32 + 4
  // must not wrap to 4.
  for (const json& bad : {json(2), json(0), json(4294967300LL)}) {
    EXPECT_REJECTED(lit({{{"type", "point"}, {"position", {0, 2, 0}}}}, {{"gi", {{"direct_interleave", bad}}}}),
                    "out_of_range", "/gi/direct_interleave");
  }
  EXPECT_REJECTED(lit({{{"type", "point"}, {"position", {0, 2, 0}}}}, {{"gi", {{"direct_interleave", true}}}}),
                  "wrong_type", "/gi/direct_interleave");
  EXPECT_REJECTED(lit({{{"type", "point"}, {"position", {0, 2, 0}}}}, {{"gi", {{"splat_scale", 9}}}}),
                  "out_of_range", "/gi/splat_scale");
  // 0 is the default, auto (8 from 512 pixels a side, else 4).
  EXPECT_EQ(parse_scene(lit({{{"type", "point"}, {"position", {0, 2, 0}}}}), {}).gi.splat_scale, 0);
  EXPECT_EQ(parse_scene(lit({{{"type", "point"}, {"position", {0, 2, 0}}}}), {}).gi.direct_interleave, 4);
}

TEST(Lights, BadMaterialsAreRefusedWithTheirPath) {
  auto with_material = [](json m) {
    json j = lit({{{"type", "point"}, {"position", {0, 2, 0}}}});
    j["occluders"][0]["material"] = std::move(m);
    return j;
  };
  EXPECT_REJECTED(with_material({{"type", "glass"}, {"ior", 0}}), "out_of_range", "/occluders/0/material/ior");
  EXPECT_REJECTED(with_material({{"type", "glass"}, {"ior", -1.5}}), "out_of_range",
                  "/occluders/0/material/ior");
  EXPECT_REJECTED(with_material({{"type", "mirror"}, {"reflectance", {1.2, 1, 1}}}), "out_of_range",
                  "/occluders/0/material/reflectance/0");
  EXPECT_REJECTED(with_material({{"type", "metal"}}), "invalid_value", "/occluders/0/material/type");
  EXPECT_REJECTED(with_material({{"type", "mirror"}, {"ior", 1.5}}), "unknown_field",
                  "/occluders/0/material/ior");
  json twice = with_material({{"type", "diffuse"}, {"albedo", {0.5, 0.5, 0.5}}});
  twice["occluders"][0]["albedo"] = {0.1, 0.1, 0.1};
  EXPECT_REJECTED(twice, "invalid_value", "/occluders/0/material/albedo");
}

TEST(Lights, PhotonCountsAreLimited) {
  SceneLimits limits;
  limits.max_photons = 1000;
  auto gi = [](json g) { return lit({{{"type", "point"}, {"position", {0, 2, 0}}}}, {{"gi", g}}); };
  ErrorInfo e = error_of(gi({{"photons", 1001}}), limits);
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_EQ(e.path, "/gi/photons");
  EXPECT_NE(e.message.find("max_photons"), std::string::npos) << e.message;
  e = error_of(gi({{"photons", 600}, {"caustic_photons", 401}}), limits);
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_EQ(e.path, "/gi/caustic_photons");
  e = error_of(gi({{"photons", -1}}), limits);
  EXPECT_EQ(e.code, "out_of_range");
  e = error_of(gi({{"kernel", "gauss"}}), limits);
  EXPECT_EQ(e.path, "/gi/kernel");
  e = error_of(gi({{"max_depth", 0}}), limits);
  EXPECT_EQ(e.path, "/gi/max_depth");
  // Defaults are clipped to the limit rather than refused.
  SceneLoadOptions o;
  o.limits = limits;
  const Scene s = parse_scene(lit({{{"type", "point"}, {"position", {0, 2, 0}}}}), o);
  EXPECT_LE(s.gi.photons + s.gi.caustic_photons, 1000);
  // Lights are limited too.
  limits.max_lights = 1;
  e = error_of(lit({{{"type", "point"}, {"position", {0, 2, 0}}}, {{"type", "point"}, {"position", {0, 1, 0}}}}),
               limits);
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_EQ(e.path, "/lights");
}

// The direct pass's settings: the method by name, the knobs in range, and
// its shadow maps within max_shadow_texels (16 quad points x 6 faces x
// 256^2 = 6 291 456 texels by default; one point light x 6 x 64^2 = 24 576).
TEST(Lights, DirectLightSettingsAndTheShadowBudget) {
  const json quad = {{"type", "quad"}, {"corner", {0, 2, 0}}, {"edge_u", {1, 0, 0}},
                     {"edge_v", {0, 0, 1}}};
  auto gi = [&](json g) { return lit(json::array({quad}), {{"gi", g}}); };
  const Scene s = parse_scene(gi({{"direct", "photons"}, {"direct_samples", 9}, {"shadow_size", 64}}),
                              {});
  EXPECT_EQ(s.gi.direct, DirectLightMethod::kPhotons);
  EXPECT_EQ(s.gi.direct_samples, 9);
  EXPECT_EQ(s.gi.shadow_size, 64);
  EXPECT_EQ(parse_scene(gi(json::object()), {}).gi.direct, DirectLightMethod::kShadowMaps);
  EXPECT_REJECTED(gi({{"direct", "rays"}}), "invalid_value", "/gi/direct");
  EXPECT_REJECTED(gi({{"direct_samples", 0}}), "out_of_range", "/gi/direct_samples");
  EXPECT_REJECTED(gi({{"shadow_size", 8}}), "out_of_range", "/gi/shadow_size");
  SceneLimits limits;
  limits.max_shadow_texels = 6 * 256 * 256 * 16 - 1;
  ErrorInfo e = error_of(gi(json::object()), limits);
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_EQ(e.path, "/gi");
  EXPECT_NE(e.message.find("max_shadow_texels"), std::string::npos) << e.message;
  // Without a gi object the error points at the lights; with direct light
  // from photons there are no shadow maps to limit.
  limits.max_shadow_texels = 1000;
  EXPECT_EQ(error_of(lit(json::array({quad})), limits).path, "/lights");
  SceneLoadOptions o;
  o.limits = limits;
  EXPECT_NO_THROW(parse_scene(gi({{"direct", "photons"}}), o));
  // Each light kind's points: a point light is one isotropic point of
  // 1 / (4 pi) per unit flux, a quad's points share its flux evenly.
  const Scene q = parse_scene(lit(json::array({quad})), {});
  const auto points = std::get<QuadLight>(q.lights[0].shape).direct_points(16);
  ASSERT_EQ(points.size(), 16u);
  double total = 0.0;
  for (const DirectPoint& p : points) {
    EXPECT_EQ(p.mode, DirectPoint::Mode::kCosine);
    EXPECT_NEAR(p.position[1], 2.0, 1e-4);
    total += p.scale;
  }
  EXPECT_NEAR(total, 1.0 / std::numbers::pi, 1e-12);
}

}  // namespace
}  // namespace beamcast
