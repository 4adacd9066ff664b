// The "disk" area light (protocol/lights/disk.*): parsing and its refusals
// with their JSON paths, photon emission against the closed-form view factor
// between coaxial disks, next-event estimation and camera hits through the
// path tracer against the view factor from a point to a disk, and its
// direct-light points.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "gi/gi_scene.hpp"
#include "gi/path_tracer.hpp"
#include "gi/photon_map.hpp"
#include "protocol/errors.hpp"
#include "protocol/lights/disk.hpp"
#include "protocol/scene_json.hpp"
#include "tests/common/lit_shapes.hpp"

namespace beamcast {
namespace {

using nlohmann::json;
constexpr double kPi = std::numbers::pi;

// A disk light (center (0, h, 0), facing `normal`, radius R) over a diffuse
// floor y = 0 of albedo rho.
json disk_scene(double h, double R, const json& normal, double rho, json light_extra = {}) {
  json light = {{"type", "disk"}, {"center", {0, h, 0}}, {"normal", normal}, {"radius", R}};
  if (light_extra.is_object()) light.update(light_extra);
  return {{"occluders", {{{"type", "plane"}, {"point", {0, 0, 0}}, {"normal", {0, 1, 0}},
                          {"albedo", {rho, rho, rho}}}}},
          {"lights", json::array({light})},
          {"cameras", {{{"position", {2, 1, 0.3}}, {"target", {0, 0, 0}}}}}};
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

TEST(DiskLight, ParsesWithItsFluxAndFrame) {
  const Scene s = parse_scene(disk_scene(2.0, 0.5, {0, -3, 0}, 0.5, {{"radiance", {4, 2, 1}}}), {});
  ASSERT_EQ(s.lights.size(), 1u);
  const auto& d = std::get<DiskLight>(s.lights[0].shape);
  EXPECT_NEAR(d.area, kPi * 0.25, 1e-15);
  EXPECT_NEAR(d.normal[1], -1.0, 1e-15);  // normalized
  // Radiance L: flux pi A L, and radiance_scale() x flux gives L back.
  EXPECT_NEAR(s.lights[0].flux[0], kPi * d.area * 4.0, 1e-12);
  EXPECT_NEAR(d.radiance_scale() * s.lights[0].flux[1], 2.0, 1e-12);
  // The frame is right-handed and orthonormal; the outline is the square
  // about the disk, facing along the normal.
  EXPECT_NEAR(dot(d.t, d.b), 0.0, 1e-15);
  const Vec3 n = cross(d.t, d.b);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(n[k], d.normal[k], 1e-15);
  const LightOutline o = *d.outline();
  EXPECT_EQ(o.code, DiskLight::kOutlineCode);
  const Vec3 mid = o.corner + 0.5 * o.u + 0.5 * o.v;
  const Vec3 on = normalize(cross(o.u, o.v));
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(mid[k], d.center[k], 1e-15);
    EXPECT_NEAR(on[k], d.normal[k], 1e-15);
  }
  EXPECT_NEAR(length(o.u), 1.0, 1e-15);
  // Facing down, its bounds are flat in y and 2R wide in x and z.
  const Aabb b = d.bounds();
  EXPECT_NEAR(b.hi[0] - b.lo[0], 1.0, 1e-15);
  EXPECT_NEAR(b.hi[1] - b.lo[1], 0.0, 1e-15);
}

TEST(DiskLight, BadFieldsAreRefusedWithTheirPath) {
  struct Case {
    json extra;  // replaces fields of the light
    const char* code;
    const char* path;
  };
  const std::vector<Case> cases = {
      {{{"radius", 0}}, "out_of_range", "/lights/0/radius"},
      {{{"radius", -1}}, "out_of_range", "/lights/0/radius"},
      {{{"radius", 1e-310}}, "out_of_range", "/lights/0/radius"},  // denormal
      {{{"radius", 1e-16}}, "out_of_range", "/lights/0/radius"},   // area below float's normals
      {{{"radius", 1e300}}, "out_of_range", "/lights/0/radius"},   // max_abs_coordinate
      {{{"radius", "big"}}, "wrong_type", "/lights/0/radius"},
      {{{"radius", nullptr}}, "wrong_type", "/lights/0/radius"},  // what NaN serializes to
      {{{"normal", {0, 0, 0}}}, "invalid_value", "/lights/0/normal"},
      {{{"normal", {0, -1e-310, 0}}}, "out_of_range", "/lights/0/normal/1"},  // subnormal
      {{{"normal", {0, 1}}}, "wrong_type", "/lights/0/normal"},
      {{{"center", {0, 1e300, 0}}}, "out_of_range", "/lights/0/center/1"},
      {{{"edge_u", {1, 0, 0}}}, "unknown_field", "/lights/0/edge_u"},
      {{{"radiance", {1, 1, 1}}, {"power", 2}}, "invalid_value", "/lights/0/radiance"},
      // The smallest disk (radius 1e-15) with a power of 1e3 would have
      // radiance 1e3 / (pi^2 1e-30) = 1e32, over the limit 1e30.
      {{{"radius", 1e-15}, {"power", 1e3}}, "out_of_range", "/lights/0"},
  };
  for (const Case& c : cases) {
    json j = disk_scene(1.0, 0.5, {0, -1, 0}, 0.5);
    j["lights"][0].update(c.extra);
    const ErrorInfo e = error_of(j);
    EXPECT_EQ(e.code, c.code) << c.extra.dump() << ": " << e.message;
    EXPECT_EQ(e.path, c.path) << c.extra.dump() << ": " << e.message;
    EXPECT_FALSE(e.message.empty());
  }
  for (const char* field : {"center", "normal", "radius"}) {
    json j = disk_scene(1.0, 0.5, {0, -1, 0}, 0.5);
    j["lights"][0].erase(field);
    const ErrorInfo e = error_of(j);
    EXPECT_EQ(e.code, "missing_field") << field;
    EXPECT_EQ(e.path, std::string("/lights/0/") + field);
  }
  // A normal is a direction whatever its length (scale-free): a tiny one,
  // and one whose length overflows a double.
  const Scene tiny = parse_scene(disk_scene(1.0, 0.5, {0, -1e-300, 0}, 0.5), {});
  EXPECT_NEAR(std::get<DiskLight>(tiny.lights[0].shape).normal[1], -1.0, 1e-15);
  const Scene huge = parse_scene(disk_scene(1.0, 0.5, {1e308, -1e308, 0}, 0.5), {});
  const DiskLight& d = std::get<DiskLight>(huge.lights[0].shape);
  EXPECT_NEAR(d.normal[0], std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(d.normal[1], -std::sqrt(0.5), 1e-15);
  EXPECT_TRUE(std::isfinite(d.t[0]) && std::isfinite(d.b[0]));
}

// The flux of a uniform Lambertian disk (radius R) that reaches a coaxial
// parallel disk (radius r) at distance h is P F with the view factor
//   F = (X - sqrt(X^2 - 4 (r/R)^2)) / 2,  X = 1 + (1 + (r/h)^2) / (R/h)^2;
// as r -> 0, F -> r^2 / (R^2 + h^2), i.e. the on-axis irradiance
// E = P / (pi (R^2 + h^2)) (= pi L R^2 / (R^2 + h^2) with L = P / (pi^2 R^2)).
double disk_to_disk(double R, double r, double h) {
  const double a = R / h, b = r / h;
  const double X = 1.0 + (1.0 + b * b) / (a * a);
  return 0.5 * (X - std::sqrt(X * X - 4.0 * (b / a) * (b / a)));
}

TEST(DiskLight, PhotonsOnAFloorMatchTheDiskToDiskViewFactor) {
  constexpr double kH = 1.0, kR = 0.5, kPower = 2.0;
  constexpr std::int64_t kPhotons = 200000;
  json j = disk_scene(kH, kR, {0, -1, 0}, 0.0, {{"power", kPower}});
  j["gi"] = {{"photons", kPhotons}, {"caustic_photons", 0}};
  const Scene scene = parse_scene(j, {});
  const GiScene surfaces(scene);
  const PhotonMaps maps = trace_photons(scene, surfaces);
  // Every photon leaves the front face downwards and lands on the black floor once.
  ASSERT_EQ(static_cast<std::int64_t>(maps.global.size()), kPhotons);
  for (const double r : {0.1, 0.5, 1.5}) {
    double power = 0.0;
    for (const Photon& p : maps.global) {
      if (p.p[0] * p.p[0] + p.p[2] * p.p[2] <= r * r) power += p.power[0];
    }
    const double F = disk_to_disk(kR, r, kH);
    // Each photon lands inside with probability F: relative standard error
    // sqrt((1 - F) / (F N)) (2.5% at r = 0.1, 0.2% at 1.5); 4 of them.
    const double se = std::sqrt((1.0 - F) / (F * kPhotons));
    std::printf("disk light photons within r = %.1f: %.5f of the power, view factor %.5f (%+.2f%%, se %.2f%%)\n",
                r, power / kPower, F, 100.0 * (power / kPower / F - 1.0), 100.0 * se);
    EXPECT_NEAR(power / kPower, F, 4.0 * se * F) << r;
  }
  // Facing up, away from the floor, no photon reaches it (one-sided).
  json up = disk_scene(kH, kR, {0, 1, 0}, 0.0);
  up["gi"] = {{"photons", 20000}, {"caustic_photons", 0}};
  const Scene up_scene = parse_scene(up, {});
  const GiScene up_surfaces(up_scene);
  EXPECT_TRUE(trace_photons(up_scene, up_surfaces).global.empty());
}

using test::make_camera;

// The path tracer's floor under the disk: its radiance is rho L F with F =
// R^2 / (R^2 + h^2), the view factor from a floor point on the axis to the
// disk (every path after the first bounce leaves the open scene or ends on
// the light, which next-event estimation has already counted).
TEST(DiskLight, PathTracedFloorIsRhoLTimesTheViewFactor) {
  constexpr double kH = 0.8, kR = 0.6, kRho = 0.6, kL = 3.0;
  json j = disk_scene(kH, kR, {0, -1, 0}, kRho, {{"radiance", {kL, kL, kL}}});
  const Scene scene = parse_scene(j, {});
  const GiScene gi(scene);
  // Looking at the point under the centre from beside the light; the pixels
  // see a spot 0.02 wide, where F varies < 1e-4.
  const Camera cam = make_camera({2.0, 1.0, 0.3}, {0.0, 0.0, 0.0}, 0.5, 16, 16);
  PathTraceOptions po;
  po.spp = 64;
  const std::vector<Color> img = path_trace(gi, cam, po);
  double s = 0.0, s2 = 0.0;
  for (const Color& c : img) {
    s += c[0];
    s2 += c[0] * c[0];
  }
  const double n = static_cast<double>(img.size());
  const double mean = s / n, se = std::sqrt(std::max(0.0, (s2 - n * mean * mean) / (n - 1.0)) / n);
  const double expected = kRho * kL * kR * kR / (kR * kR + kH * kH);
  std::printf("floor under disk light: %.6f expected %.6f (%+.3f%%, standard error %.3f%%)\n", mean,
              expected, 100.0 * (mean / expected - 1.0), 100.0 * se / expected);
  EXPECT_LT(se / expected, 0.01);
  EXPECT_NEAR(mean, expected, 5.0 * se);
}

TEST(DiskLight, SeenFromItsFrontItsRadianceFromBehindNothing) {
  Scene scene;
  const Color L{17.0, 12.0, 4.0};
  Light l;
  const DiskLight d = DiskLight::make({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 2.0);
  l.shape = d;
  l.flux = (1.0 / d.radiance_scale()) * L;
  scene.lights.push_back(l);
  scene.background = {0.1, 0.2, 0.3};
  const GiScene gi(scene);
  // Every pixel of a narrow view of the centre sees the disk.
  const Camera front = make_camera({0.3, 0.1, 3.0}, {0.0, 0.0, 0.0}, 10.0, 8, 8);
  for (const Color& c : path_trace(gi, front, PathTraceOptions{.spp = 4})) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], L[k], 1e-12 * L[k]);
  }
  const Camera back = make_camera({0.0, 0.0, -3.0}, {0.0, 0.0, 0.0}, 10.0, 4, 4);
  for (const Color& c : path_trace(gi, back, PathTraceOptions{.spp = 2})) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(c[k], scene.background[k]);
  }
  // Just past the rim a ray misses; just inside it hits.
  EXPECT_TRUE(d.hit({1.999, 0.0, 1.0}, {0.0, 0.0, -1.0}, 10.0).has_value());
  EXPECT_FALSE(d.hit({0.0, 2.001, 1.0}, {0.0, 0.0, -1.0}, 10.0).has_value());
}

TEST(DiskLight, DirectPointsShareItsFluxOverTheDisk) {
  const DiskLight d = DiskLight::make({1.0, 2.0, 3.0}, {0.0, -1.0, 0.0}, 0.5);
  const std::vector<DirectPoint> points = d.direct_points(16);
  ASSERT_EQ(points.size(), 16u);
  double total = 0.0;
  Vec3 quarter[4]{};
  for (std::size_t i = 0; i < points.size(); ++i) {
    const DirectPoint& p = points[i];
    total += p.scale;
    EXPECT_EQ(p.mode, DirectPoint::Mode::kCosine);
    const Vec3 r = p.position - d.center;
    EXPECT_LT(length(r), 0.5);
    EXPECT_NEAR(r[1], -5e-6, 1e-12);  // lifted in front of its face
    quarter[i % 4] = quarter[i % 4] + 0.25 * r;
  }
  // A point light's 1 / pi per unit flux over the hemisphere, in all.
  EXPECT_NEAR(total, 1.0 / kPi, 1e-12);
  // Each interleaved quarter spans the disk: its points' mean lies near the
  // centre (a quarter of a 4 x 4 grid's 2 x 2 blocks: within a cell).
  for (const Vec3& q : quarter) EXPECT_LT(std::hypot(q[0], q[2]), 0.5 / 2.0);
}

}  // namespace
}  // namespace beamcast
