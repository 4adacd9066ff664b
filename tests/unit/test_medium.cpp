// The participating medium in the scene format (issue 15, item 1): "medium"
// parses to the model, plans the medium pass only when it attenuates, and
// every bad field is refused with its JSON pointer.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "protocol/errors.hpp"
#include "protocol/scene_json.hpp"
#include "render/pass_plan.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

json fogged(json medium) {
  return {{"beams", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1.0}}}},
          {"medium", std::move(medium)},
          {"cameras", {{{"position", {0, 0, 5}}, {"target", {0, 0, 0}}}}}};
}

ErrorInfo error_of(const json& j) {
  try {
    parse_scene(j, {});
  } catch (const ProtocolError& e) {
    return e.info();
  }
  ADD_FAILURE() << "scene was accepted: " << j.dump();
  return {};
}

TEST(Medium, ParsesCoefficientsPhaseAndKnobs) {
  const Scene s = parse_scene(fogged({{"sigma_s", 0.2}, {"sigma_a", 0.05}, {"g", 0.5},
                                      {"beam_rule", "midpoint"}, {"beam_step", 0.5},
                                      {"segments", 8}}),
                              {});
  ASSERT_TRUE(s.medium.has_value());
  EXPECT_DOUBLE_EQ(s.medium->sigma_t(), 0.25);
  EXPECT_NEAR(s.medium->k, 0.70625, 1e-12);  // 1.55 g - 0.55 g^3 at g = 0.5
  EXPECT_EQ(s.medium->beam_rule, BeamMediumRule::kMidpoint);
  EXPECT_DOUBLE_EQ(s.medium->beam_step, 0.5);
  EXPECT_EQ(s.medium->segments, 8);
  const Scene k = parse_scene(fogged({{"sigma_a", 1.0}, {"k", -0.3}}), {});
  EXPECT_DOUBLE_EQ(k.medium->k, -0.3);
  EXPECT_EQ(k.medium->beam_rule, BeamMediumRule::kGauss2);  // the default
  EXPECT_EQ(k.medium->segments, 0);                         // exact
}

// The pass runs only when the medium attenuates: none, or a medium with
// sigma_t = 0, plans exactly what the scene planned before media existed.
TEST(Medium, TheMediumPassIsPlannedOnlyWhenSomethingAttenuates) {
  json clear = fogged(json::object());
  clear.erase("medium");
  const auto has_medium_pass = [](const json& j) {
    const std::vector<std::string> p = plan_passes(parse_scene(j, {}));
    return std::find(p.begin(), p.end(), "medium") != p.end();
  };
  EXPECT_FALSE(has_medium_pass(clear));
  EXPECT_FALSE(has_medium_pass(fogged({{"sigma_s", 0.0}})));
  EXPECT_TRUE(has_medium_pass(fogged({{"sigma_s", 0.1}})));
  EXPECT_EQ(plan_passes(parse_scene(fogged({{"sigma_a", 0.1}}), {})),
            (std::vector<std::string>{"medium", "beams", "tonemap"}));
  // Volume photons: only a lit scene whose medium scatters.
  json lit = fogged({{"sigma_s", 0.1}});
  lit["lights"] = {{{"type", "point"}, {"position", {0, 3, 0}}, {"power", 10}}};
  const auto has_pass = [](const json& j, const char* name) {
    const std::vector<std::string> p = plan_passes(parse_scene(j, {}));
    return std::find(p.begin(), p.end(), name) != p.end();
  };
  const auto has_volume_pass = [&](const json& j) {
    return has_pass(j, "volume_photons") || has_pass(j, "volume_grid");
  };
  EXPECT_TRUE(has_volume_pass(lit));
  // The grid (the default) or the splats (medium.estimator "beam", "seed"), never both.
  EXPECT_TRUE(has_pass(lit, "volume_grid"));
  EXPECT_FALSE(has_pass(lit, "volume_photons"));
  for (const char* splats : {"beam", "seed"}) {
    json s = lit;
    s["medium"]["estimator"] = splats;
    EXPECT_TRUE(has_pass(s, "volume_photons")) << splats;
    EXPECT_FALSE(has_pass(s, "volume_grid")) << splats;
  }
  lit["medium"] = {{"sigma_a", 0.1}};
  EXPECT_FALSE(has_volume_pass(lit));
  EXPECT_FALSE(has_volume_pass(fogged({{"sigma_s", 0.1}})));
}

TEST(Medium, PhotonLodParsesWithItsDefaults) {
  json j = fogged({{"sigma_s", 0.1}});
  j["gi"] = {{"lod", {{"near", 25}, {"far", 3}}}};
  const Scene s = parse_scene(j, {});
  EXPECT_EQ(s.gi.lod_groups, 16);
  EXPECT_DOUBLE_EQ(s.gi.lod_near, 25.0);
  EXPECT_DOUBLE_EQ(s.gi.lod_far, 3.0);
  EXPECT_EQ(parse_scene(fogged({{"sigma_s", 0.1}}), {}).gi.lod_groups, 0);  // off unless asked
  j["gi"]["lod"] = {{"near", 3}, {"far", 3}};
  EXPECT_EQ(error_of(j).path, "/gi/lod/far");
  j["gi"]["lod"] = {{"near", 3}, {"far", 5}, {"groups", 0}};
  EXPECT_EQ(error_of(j).path, "/gi/lod/groups");
  j["gi"]["lod"] = {{"near", -1}, {"far", 5}};
  EXPECT_EQ(error_of(j).path, "/gi/lod/near");
  j["gi"]["lod"] = {{"far", 5}};
  EXPECT_EQ(error_of(j).code, "missing_field");
}

// Regions of medium ("media"): parsed, planned, and their optical depth is
// the sum of sigma_t times exact chords (a box and a sphere against a
// midpoint sum over 1e5 steps: 1e-9 covers the sum's own error).
TEST(Medium, RegionsParseAndTheirOpticalDepthIsExact) {
  json j = fogged(json::object());
  j.erase("medium");
  j["media"] = {{{"type", "box"}, {"min", {-1, -1, -1}}, {"max", {1, 0.5, 2}}, {"sigma_a", 0.5}},
                {{"type", "sphere"}, {"center", {0.5, 0, 0}}, {"radius", 1.0}, {"sigma_s", 2.0},
                 {"g", 0.3}}};
  const Scene s = parse_scene(j, {});
  ASSERT_EQ(s.media.size(), 2u);
  EXPECT_TRUE(s.has_medium());
  EXPECT_FALSE(s.global_medium());
  const std::vector<std::string> p = plan_passes(s);
  EXPECT_NE(std::find(p.begin(), p.end(), "medium"), p.end());
  const MediumField field = s.medium_field();
  EXPECT_DOUBLE_EQ(field.majorant(), 2.5);
  EXPECT_DOUBLE_EQ(field.sigma_t({0.5, 0.0, 0.0}), 2.5);   // both
  EXPECT_DOUBLE_EQ(field.sigma_t({0.5, 0.9, 0.0}), 2.0);   // the sphere only
  EXPECT_DOUBLE_EQ(field.sigma_t({-0.9, -0.9, 1.5}), 0.5);  // the box only
  EXPECT_NEAR(field.k({0.5, 0.0, 0.0}), 1.55 * 0.3 - 0.55 * 0.027, 1e-12);
  const Vec3 o{-3.0, 0.2, 0.1};
  const Vec3 v = normalize(Vec3{1.0, -0.05, 0.02});
  const int n = 100000;
  const double len = 6.0;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += field.sigma_t(o + ((i + 0.5) * len / n) * v);
  EXPECT_NEAR(field.optical_depth(o, v, 0.0, len), sum * len / n, 1e-4);
  EXPECT_GT(field.optical_depth(o, v, 0.0, len), 1.0);
  EXPECT_DOUBLE_EQ(field.last_exit(o, v) > 3.0, true);
}

// MediumField::free_path inverts the optical depth exactly, segment by
// segment, whatever the ratio of the regions' extinction to the fog's
// (issue 43: delta tracking against a majorant of 1 in fog of 1e-300 never
// ended), and every free path ends before the medium's extent.
TEST(Medium, FreePathInvertsTheOpticalDepthAndEnds) {
  json j = fogged({{"sigma_s", 1e-300}});
  j["media"] = {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1.0}, {"sigma_s", 1.0}},
                {{"type", "box"}, {"min", {2, -1, -1}}, {"max", {3, 1, 1}}, {"sigma_s", 1e6}}};
  const Scene s = parse_scene(j, {});
  const MediumField field = s.medium_field();
  const Vec3 o{-2.0, 0.1, 0.0};
  const Vec3 v = normalize(Vec3{1.0, 0.0, 0.01});
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // tau below the sphere's chord (~2), past it into the box, and past both.
  for (const double tau : {0.0, 0.5, 1.9, 2.5, 1e5, 3e6}) {
    const double t = field.free_path(o, v, kInf, tau);
    if (tau > 2.0 + 1e6) {
      // Beyond the box only fog of 1e-300: the path ends at the extent, no event.
      EXPECT_EQ(t, kInf) << tau;
      continue;
    }
    ASSERT_TRUE(std::isfinite(t)) << tau;
    // Relative 1e-9: the sum of a few segments' exact depths in double.
    EXPECT_NEAR(field.optical_depth(o, v, 0.0, t), tau, 1e-9 * std::max(1.0, tau)) << tau;
  }
  // Not before t_end: no event.
  EXPECT_EQ(field.free_path(o, v, 0.5, 2.5), kInf);
  // Fog alone: t = tau / sigma_t, the same numbers as before; none past the extent.
  const Scene fog = parse_scene(fogged({{"sigma_s", 0.25}}), {});
  EXPECT_DOUBLE_EQ(fog.medium_field().free_path(o, v, kInf, 2.0), 8.0);
  EXPECT_EQ(fog.medium_field().free_path(o, v, kInf, 1e12), kInf);
}

TEST(Medium, BadFieldsAreRefusedWithTheirPath) {
  struct Case {
    json medium;
    std::string code, path;
  };
  const Case cases[] = {
      {{{"sigma_s", -0.1}}, "out_of_range", "/medium/sigma_s"},
      {{{"sigma_a", -1e-9}}, "out_of_range", "/medium/sigma_a"},
      {{{"sigma_a", 1e7}}, "out_of_range", "/medium/sigma_a"},
      {{{"g", 1.0}}, "out_of_range", "/medium/g"},
      {{{"g", -0.95}}, "out_of_range", "/medium/g"},
      {{{"k", 1.0}}, "out_of_range", "/medium/k"},
      {{{"k", -1.0}}, "out_of_range", "/medium/k"},
      {{{"k", 0.2}, {"g", 0.2}}, "invalid_value", "/medium/g"},
      {{{"sigma_s", "thick"}}, "wrong_type", "/medium/sigma_s"},
      {{{"beam_rule", "simpson"}}, "invalid_value", "/medium/beam_rule"},
      {{{"beam_step", 0.0}}, "out_of_range", "/medium/beam_step"},
      {{{"estimator", "froxel"}}, "invalid_value", "/medium/estimator"},
      {{{"radius", -1.0}}, "out_of_range", "/medium/radius"},
      {{{"segments", 257}}, "out_of_range", "/medium/segments"},
      {{{"segments", -1}}, "out_of_range", "/medium/segments"},
      {{{"density", 1.0}}, "unknown_field", "/medium/density"},
      {json::array(), "wrong_type", "/medium"},
  };
  struct RegionCase {
    json region;
    std::string code, path;
  };
  const RegionCase region_cases[] = {
      {{{"type", "box"}, {"min", {0, 0, 0}}, {"max", {1, 0, 1}}}, "invalid_value", "/media/0/max"},
      {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", -1}}, "out_of_range",
       "/media/0/radius"},
      {{{"type", "cone"}}, "invalid_value", "/media/0/type"},
      {{{"type", "box"}, {"min", {0, 0, 0}}}, "missing_field", "/media/0/max"},
      {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1}, {"sigma_s", -2}},
       "out_of_range", "/media/0/sigma_s"},
      {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1}, {"min", {0, 0, 0}}},
       "unknown_field", "/media/0/min"},
  };
  for (const RegionCase& c : region_cases) {
    json j = fogged(json::object());
    j["media"] = json::array({c.region});
    const ErrorInfo e = error_of(j);
    EXPECT_EQ(e.code, c.code) << c.region.dump() << ": " << e.message;
    EXPECT_EQ(e.path, c.path) << c.region.dump() << ": " << e.message;
  }
  json many = fogged(json::object());
  many["media"] = json::array();
  for (int i = 0; i <= kMaxMediumRegions; ++i) {
    many["media"].push_back({{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1}});
  }
  EXPECT_EQ(error_of(many).code, "limit_exceeded");
  for (const Case& c : cases) {
    const ErrorInfo e = error_of(fogged(c.medium));
    EXPECT_EQ(e.code, c.code) << c.medium.dump() << ": " << e.message;
    EXPECT_EQ(e.path, c.path) << c.medium.dump() << ": " << e.message;
    EXPECT_FALSE(e.message.empty());
  }
}

}  // namespace
}  // namespace beamcast
