// The "cylinder" medium region (fog shaped like a beam; issue 41): parsed
// with its bad fields refused at their JSON pointer, and its membership,
// chords and free paths exact against a midpoint sum of its point test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <variant>

#include "protocol/errors.hpp"
#include "protocol/scene_json.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

json with_region(json region) {
  return {{"beams", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1.0}}}},
          {"media", json::array({std::move(region)})},
          {"cameras", {{{"position", {0, 0, 5}}, {"target", {0, 0, 0}}}}}};
}

json cylinder(const Vec3& p0, const Vec3& p1, double radius) {
  return {{"type", "cylinder"},
          {"p0", {p0[0], p0[1], p0[2]}},
          {"p1", {p1[0], p1[1], p1[2]}},
          {"radius", radius},
          {"sigma_a", 0.5}};
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

// Membership at points chosen about the axis, exact chords on lines through
// it, and the optical depth of oblique rays against a midpoint sum of the
// point test over 1e5 steps (1e-4: the sum's own error at the two ends and
// two sides, about 4 x sigma_t x step).
TEST(MediumCylinder, ItsPointTestChordsAndFreePathsAgree) {
  const Vec3 p0{-1.0, -0.5, 0.2}, p1{2.0, 1.0, -0.4};
  const Scene s = parse_scene(with_region(cylinder(p0, p1, 0.6)), {});
  ASSERT_EQ(s.media.size(), 1u);
  const auto& c = std::get<CylinderRegion>(s.media[0].shape);
  const Vec3 u = normalize(p1 - p0);
  const Vec3 side = normalize(cross(u, Vec3{0.0, 0.0, 1.0}));
  const double len = length(p1 - p0);
  const Vec3 mid = 0.5 * (p0 + p1);
  EXPECT_TRUE(c.contains(mid));
  EXPECT_TRUE(c.contains(mid + 0.59 * side));
  EXPECT_FALSE(c.contains(mid + 0.61 * side));
  EXPECT_TRUE(c.contains(p0 + 0.01 * u));
  EXPECT_FALSE(c.contains(p0 - 0.01 * u));
  EXPECT_FALSE(c.contains(p1 + 0.01 * u));
  // Across the axis: the diameter; along it from outside: the length.
  EXPECT_NEAR(c.chord(mid - 3.0 * side, side, 0.0, 10.0), 1.2, 1e-12);
  EXPECT_NEAR(c.chord(p0 - 2.0 * u, u, 0.0, 10.0), len, 1e-12);
  EXPECT_NEAR(c.exit(p0 - 2.0 * u + 0.3 * side, u), 2.0 + len, 1e-12);
  EXPECT_EQ(c.chord(p0 - 2.0 * u + 0.7 * side, u, 0.0, 10.0), 0.0);  // beside it, parallel
  // The bounds hold the caps' rims, and are tight along each axis.
  const Aabb b = c.bounds();
  for (int i = 0; i < 64; ++i) {
    const double phi = 2.0 * M_PI * i / 64.0;
    const Vec3 rim = 0.6 * (std::cos(phi) * side + std::sin(phi) * normalize(cross(u, side)));
    for (const Vec3& p : {p0 + rim, p1 + rim}) {
      for (std::size_t k = 0; k < 3; ++k) {
        EXPECT_GE(p[k], b.lo[k] - 1e-12);
        EXPECT_LE(p[k], b.hi[k] + 1e-12);
      }
    }
  }
  EXPECT_NEAR(b.hi[2], std::max(p0[2], p1[2]) + 0.6 * std::sqrt(1.0 - u[2] * u[2]), 1e-12);
  const MediumField field = s.medium_field();
  const Vec3 origins[] = {{-3.0, 0.2, 0.1}, {0.3, 0.2, 3.0}, {-2.5, -1.2, 0.3}};
  const Vec3 dirs[] = {{1.0, -0.05, 0.02}, {0.05, -0.02, -1.0}, {1.0, 0.5, -0.2}};
  for (int r = 0; r < 3; ++r) {
    const Vec3 o = origins[r];
    const Vec3 v = normalize(dirs[r]);
    constexpr int n = 100000;
    constexpr double kLen = 6.0;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += field.sigma_t(o + ((i + 0.5) * kLen / n) * v);
    const double depth = field.optical_depth(o, v, 0.0, kLen);
    EXPECT_GT(depth, 0.1) << r;
    EXPECT_NEAR(depth, sum * kLen / n, 1e-4) << r;
    const double t = field.free_path(o, v, kLen, 0.5 * depth);
    EXPECT_NEAR(field.optical_depth(o, v, 0.0, t), 0.5 * depth, 1e-12) << r;
  }
}

TEST(MediumCylinder, BadFieldsAreRefusedWithTheirPath) {
  const double kInf = std::numeric_limits<double>::infinity();
  json no_p0 = cylinder({0, 0, 0}, {1, 0, 0}, 1.0);
  no_p0.erase("p0");
  json no_p1 = cylinder({0, 0, 0}, {1, 0, 0}, 1.0);
  no_p1.erase("p1");
  json no_radius = cylinder({0, 0, 0}, {1, 0, 0}, 1.0);
  no_radius.erase("radius");
  json boxy = cylinder({0, 0, 0}, {1, 0, 0}, 1.0);
  boxy["min"] = {0, 0, 0};
  json worded = cylinder({0, 0, 0}, {1, 0, 0}, 1.0);
  worded["radius"] = "wide";
  struct Case {
    json region;
    std::string code, path;
  };
  const Case cases[] = {
      {cylinder({0, 0, 0}, {1, 0, 0}, 0.0), "out_of_range", "/media/0/radius"},
      {cylinder({0, 0, 0}, {1, 0, 0}, -0.5), "out_of_range", "/media/0/radius"},
      {cylinder({0, 0, 0}, {1, 0, 0}, kInf), "not_finite", "/media/0/radius"},
      {cylinder({0, 0, 0}, {1, 0, 0}, 1e300), "out_of_range", "/media/0/radius"},
      {worded, "wrong_type", "/media/0/radius"},
      {cylinder({1, 2, 3}, {1, 2, 3}, 1.0), "invalid_value", "/media/0/p1"},
      // Apart in double, one point in float (as the GPU holds them).
      {cylinder({1, 2, 3}, {1, 2, 3 + 1e-12}, 1.0), "invalid_value", "/media/0/p1"},
      {cylinder({0, 0, 0}, {kInf, 0, 0}, 1.0), "not_finite", "/media/0/p1/0"},
      {cylinder({0, 0, 1e300}, {1, 0, 0}, 1.0), "out_of_range", "/media/0/p0/2"},
      {no_p0, "missing_field", "/media/0/p0"},
      {no_p1, "missing_field", "/media/0/p1"},
      {no_radius, "missing_field", "/media/0/radius"},
      {boxy, "unknown_field", "/media/0/min"},
  };
  for (const Case& c : cases) {
    const ErrorInfo e = error_of(with_region(c.region));
    EXPECT_EQ(e.code, c.code) << c.region.dump() << ": " << e.message;
    EXPECT_EQ(e.path, c.path) << c.region.dump() << ": " << e.message;
    EXPECT_FALSE(e.message.empty());
  }
}

// hello's capabilities list the kind and its fields.
TEST(MediumCylinder, HelloListsTheKindAndItsFields) {
  const auto types = medium_region_types();
  EXPECT_NE(std::find(types.begin(), types.end(), "cylinder"), types.end());
  const auto fields = medium_region_fields();
  for (const char* f : {"p0", "p1", "radius"}) {
    EXPECT_NE(std::find(fields.begin(), fields.end(), f), fields.end()) << f;
  }
}

}  // namespace
}  // namespace beamcast
