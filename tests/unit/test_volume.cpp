// The volume model (issue 17; protocol/volume.hpp): trilinear sampling as
// GL_LINEAR does it, placement, the procedural fields against their grids,
// transfer functions, the R_v pyramid, the scene format's defaults, and
// every refusal of a bad volume or "volume" with its code and JSON pointer.
// The file readers are tested in test_volume_files.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "protocol/volume.hpp"
#include "tests/unit/volume_test_support.hpp"

namespace beamcast {
namespace {

using nlohmann::json;
using test::volume_scene;

// Double arithmetic on values of order 1: a few ulps.
constexpr double kTight = 1e-12;
// A grid value is its field value rounded to a multiple of 1/65535, so the
// two differ by at most half a step (plus the normalization's rounding).
constexpr double kQuantization = 0.5 / 65535.0 + kTight;

Volume volume_of(std::array<int, 3> dims, std::vector<std::uint16_t> q) {
  auto g = std::make_shared<VolumeGrid>();
  g->dims = dims;
  g->values = std::move(q);
  Volume v;
  v.source = VolumeSourceType::kRaw;
  v.grid = g;
  return v;
}

json ml(int resolution = 5) {
  return {{"source", {{"type", "marschner_lobb"}, {"resolution", resolution}}}};
}

TEST(VolumeSample, TrilinearIsExactForALinearField) {
  // q = 1000 (i + 3 j + 6 k): trilinear interpolation reproduces a linear
  // function exactly, and clamps to the faces outside the box.
  std::vector<std::uint16_t> q;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i)
        q.push_back(static_cast<std::uint16_t>(1000 * (i + 3 * j + 6 * k)));
  const Volume v = volume_of({3, 2, 2}, q);
  auto linear = [](double x, double y, double z) { return 1000.0 * (x + 3 * y + 6 * z) / 65535.0; };
  for (const Vec3& g : {Vec3{0, 0, 0}, Vec3{2, 1, 1}, Vec3{0.5, 0.5, 0.5}, Vec3{1.75, 0.2, 0.9},
                        Vec3{2, 0.5, 0}, Vec3{1, 1, 1}}) {
    EXPECT_NEAR(v.sample(g), linear(g[0], g[1], g[2]), kTight)
        << g[0] << " " << g[1] << " " << g[2];
  }
  EXPECT_NEAR(v.sample({-1, -3, 0.5}), linear(0, 0, 0.5), kTight);  // clamped
  EXPECT_NEAR(v.sample({7, 1.5, 9}), linear(2, 1, 1), kTight);
}

TEST(VolumeSample, TrilinearWeightsByHand) {
  // Only voxel (1, 1, 1) set: the value is the product of the weights t_x t_y t_z.
  std::vector<std::uint16_t> q(8, 0);
  q[7] = 65535;
  const Volume v = volume_of({2, 2, 2}, q);
  EXPECT_NEAR(v.sample({0.5, 0.25, 0.75}), 0.09375, kTight);
  EXPECT_NEAR(v.sample({1, 1, 0.5}), 0.5, kTight);
  EXPECT_NEAR(v.sample({0.5, 0.5, 0.5}), 0.125, kTight);
  EXPECT_EQ(v.sample({0, 1, 1}), 0.0);
  EXPECT_EQ(v.exact({0.5, 0.25, 0.75}), v.sample({0.5, 0.25, 0.75}));  // a file: no field
}

TEST(VolumeProcedural, ExactMatchesTheGridAtVoxelCentres) {
  // The grid stores each voxel centre's field value rounded to 16 bits;
  // exact() evaluates the same expression unrounded: kQuantization apart.
  for (const auto& [type, n] : {std::pair{"marschner_lobb", 41}, std::pair{"heat", 64}}) {
    const Scene s = parse_scene(volume_scene({{"source", {{"type", type}}}}), {});
    const Volume& v = s.volumes.at(0);
    ASSERT_EQ(v.grid->dims, (std::array<int, 3>{n, n, n})) << type;
    double worst = 0.0;
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          worst = std::max(
              worst, std::abs(v.exact({double(i), double(j), double(k)}) - v.grid->value(i, j, k)));
        }
    EXPECT_LE(worst, kQuantization) << type;
  }
}

TEST(VolumeProcedural, ExactIsTheFieldAtTheWorldPoint) {
  // Default placement: the grid fills [-1, 1]^3, so grid coordinate g is the
  // world point -1 + g / 20 (41^3), where exact() is the analytic field. The
  // two compute the point differently (to_world vs -1 + 2g/40): 1e-9 covers
  // that rounding times the field's slope (|grad rho| < 100).
  const Scene s = parse_scene(volume_scene({{"source", {{"type", "marschner_lobb"}}}}), {});
  const Volume& v = s.volumes[0];
  for (const Vec3& g : {Vec3{3.3, 17.9, 20.5}, Vec3{0.1, 39.7, 5.25}, Vec3{20, 20, 20}}) {
    const Vec3 w = v.to_world(g);
    EXPECT_NEAR(v.exact(g), marschner_lobb(w[0], w[1], w[2]), 1e-9);
  }
  // The classic values: rho(0, 0, 0) = (1 + 0.25 (1 + cos(12 pi))) / 2.5 = 0.6,
  // and on the top face z = 1 the sine term vanishes: rho = 0.25 (1 + cos(...)) / 2.5.
  EXPECT_NEAR(marschner_lobb(0, 0, 0), 0.6, kTight);
  EXPECT_NEAR(marschner_lobb(1, 0, 1),
              0.25 * (1 + std::cos(12 * std::numbers::pi * std::cos(std::numbers::pi / 2))) / 2.5,
              kTight);
}

TEST(VolumeProcedural, HeatIsDenseAndBelowOne) {
  const Scene s = parse_scene(volume_scene({{"source", {{"type", "heat"}}}}), {});
  const auto& q = s.volumes[0].grid->values;
  const auto [lo, hi] = std::minmax_element(q.begin(), q.end());
  // The floor of 0.05 makes every voxel non-zero (the seed's dense volume),
  // and the field spans most of [0, 1].
  EXPECT_GE(*lo, std::lround(0.05 * 65535));
  EXPECT_GT(*hi, std::lround(0.85 * 65535));
  // The documented bounds (0.05, 0.91) on a finer grid than any test volume's.
  double fmin = 1.0, fmax = 0.0;
  for (int k = 0; k <= 100; ++k)
    for (int j = 0; j <= 100; ++j)
      for (int i = 0; i <= 100; ++i) {
        const double h = heat_field(-1 + i / 50.0, -1 + j / 50.0, -1 + k / 50.0);
        fmin = std::min(fmin, h);
        fmax = std::max(fmax, h);
      }
  EXPECT_GT(fmin, 0.05);
  EXPECT_LT(fmax, 0.91);
}

TEST(VolumeProcedural, RangeNormalizesGridAndExactAlike) {
  const Scene s =
      parse_scene(volume_scene({{"source", {{"type", "marschner_lobb"}, {"resolution", 9}}},
                                {"range", {0.25, 0.75}}}),
                  {});
  const Volume& v = s.volumes[0];
  EXPECT_EQ(v.range, (std::array<double, 2>{0.25, 0.75}));
  for (int i = 0; i < 9; ++i) {
    const Vec3 g{double(i), 4.0, double(8 - i)};
    const Vec3 w = v.to_world(g);
    const double want = std::clamp((marschner_lobb(w[0], w[1], w[2]) - 0.25) / 0.5, 0.0, 1.0);
    EXPECT_NEAR(v.exact(g), want, 1e-9);
    EXPECT_NEAR(v.grid->value(i, 4, 8 - i), want, kQuantization + 1e-9);
  }
}

TEST(VolumePlacement, ProceduralDefaultsFillTheUnitCube) {
  const Scene s = parse_scene(volume_scene({{"source", {{"type", "marschner_lobb"}}}}), {});
  const Volume& v = s.volumes[0];
  EXPECT_EQ(v.source, VolumeSourceType::kMarschnerLobb);
  EXPECT_NEAR(v.spacing[0], 0.05, kTight);
  EXPECT_NEAR(v.origin[2], -1.0, kTight);
  Vec3 lo, hi;
  v.world_bounds(&lo, &hi);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(lo[a], -1.0, kTight);
    EXPECT_NEAR(hi[a], 1.0, kTight);
  }
  EXPECT_EQ(v.range, (std::array<double, 2>{0.0, 1.0}));
  EXPECT_NEAR(v.transfer.opacity_unit, 0.1, kTight);  // a twentieth of the side 2
  EXPECT_EQ(v.transfer.points.size(), transfer_preset("grey")->points.size());
  EXPECT_EQ(v.intensity, 1.0);
  EXPECT_TRUE(v.file.empty());
  // And the same from the helper the benchmarks use.
  const Volume p = procedural_volume(VolumeSourceType::kMarschnerLobb, 41, "ml");
  EXPECT_EQ(p.grid->values, v.grid->values);
  EXPECT_EQ(p.origin, v.origin);
  EXPECT_NEAR(p.spacing[1], v.spacing[1], kTight);
}

TEST(VolumePlacement, RotatedBoxStaysCentredAndMapsBack) {
  const double c = std::sqrt(0.5);  // 90 degrees about z
  const Scene s = parse_scene(volume_scene({{"source", {{"type", "heat"}, {"resolution", 5}}},
                                            {"spacing", {1.0, 0.5, 0.25}},
                                            {"rotation", {c, 0, 0, c}},
                                            {"intensity", 2.5}}),
                              {});
  const Volume& v = s.volumes[0];
  Vec3 lo, hi;
  v.world_bounds(&lo, &hi);
  // Extents 4, 2, 1 along the grid's axes; x and y swap under the rotation.
  const Vec3 want{1.0, 2.0, 0.5};
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(lo[a], -want[a], kTight);
    EXPECT_NEAR(hi[a], want[a], kTight);
  }
  for (const Vec3& p : {Vec3{0.3, -1.2, 0.4}, Vec3{-1, 2, -0.5}}) {
    const Vec3 back = v.to_world(v.to_grid(p));
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(back[a], p[a], kTight);
  }
  // Grid +x (the first axis) points along world +y.
  const Vec3 step = v.to_world({1, 0, 0}) - v.to_world({0, 0, 0});
  EXPECT_NEAR(step[1], 1.0, kTight);
  EXPECT_NEAR(v.transfer.opacity_unit, 0.2, kTight);  // largest side 4 / 20
  EXPECT_EQ(v.intensity, 2.5);
}

TEST(VolumePlacement, GivenOriginIsVoxelZero) {
  const Scene s = parse_scene(volume_scene({{"source", {{"type", "heat"}, {"resolution", 3}}},
                                            {"origin", {1, 2, 3}},
                                            {"spacing", 0.5}}),
                              {});
  const Volume& v = s.volumes[0];
  EXPECT_EQ(v.to_world({0, 0, 0}), (Vec3{1, 2, 3}));
  EXPECT_EQ(v.to_world({2, 2, 2}), (Vec3{2, 3, 4}));
  EXPECT_EQ(v.to_grid({1.5, 2.25, 3}), (Vec3{1, 0.5, 0}));
}

TEST(VolumeTransfer, PiecewiseLinearAndClamped) {
  TransferFunction tf;
  tf.points = {{0.2, {0, 0, 0}, 0.0}, {0.5, {1, 0.5, 0}, 0.8}, {1.0, {1, 1, 1}, 1.0}};
  const Color a = tf.color(0.35);
  EXPECT_NEAR(a[0], 0.5, kTight);
  EXPECT_NEAR(a[1], 0.25, kTight);
  EXPECT_NEAR(tf.opacity(0.35), 0.4, kTight);
  const Color b = tf.color(0.75);
  EXPECT_NEAR(b[1], 0.75, kTight);
  EXPECT_NEAR(b[2], 0.5, kTight);
  EXPECT_NEAR(tf.opacity(0.75), 0.9, kTight);
  EXPECT_EQ(tf.opacity(0.5), 0.8);  // at a point: its value
  EXPECT_EQ(tf.opacity(0.1), 0.0);  // below the first point: the first
  EXPECT_EQ(tf.color(0.0), (Color{0, 0, 0}));
  EXPECT_EQ(tf.opacity(3.0), 1.0);  // above the last: the last
}

TEST(VolumeTransfer, PointsAndPresetsFromJson) {
  json v = ml();
  v["transfer"] = {{"points", {{0, 0, 0, 0, 0}, {0.4, 1, 0.5, 0.25, 0.5}, {1, 2, 2, 2, 1}}},
                   {"opacity_unit", 0.02}};
  const Scene s = parse_scene(volume_scene(v), {});
  const TransferFunction& tf = s.volumes[0].transfer;
  ASSERT_EQ(tf.points.size(), 3u);
  EXPECT_EQ(tf.points[1].color, (Color{1, 0.5, 0.25}));
  EXPECT_EQ(tf.points[2].color, (Color{2, 2, 2}));  // HDR colours are fine
  EXPECT_EQ(tf.opacity_unit, 0.02);
  EXPECT_NEAR(tf.opacity(0.2), 0.25, kTight);
  for (std::string_view name : kVolumeTransferPresets) {
    v["transfer"] = {{"preset", name}};
    const Scene p = parse_scene(volume_scene(v), {});
    const auto& pts = p.volumes[0].transfer.points;
    ASSERT_GE(pts.size(), 2u) << name;
    for (std::size_t i = 1; i < pts.size(); ++i) EXPECT_GT(pts[i].value, pts[i - 1].value) << name;
  }
  // "bone": clear below 0.3, opaque white-ish above 0.5.
  const TransferFunction bone = *transfer_preset("bone");
  EXPECT_EQ(bone.opacity(0.25), 0.0);
  EXPECT_GE(bone.opacity(0.6), 0.9);
  EXPECT_GE(bone.color(0.8)[2], 0.9);
  // "ml": most opaque at the 0.5 isovalue.
  const TransferFunction m = *transfer_preset("ml");
  EXPECT_GT(m.opacity(0.5), 5 * m.opacity(0.4));
  EXPECT_FALSE(transfer_preset("rainbow"));
}

TEST(VolumePyramid, LevelSizes) {
  EXPECT_EQ(volume_level_dims({41, 41, 41}, 1), (std::array<int, 3>{21, 21, 21}));
  EXPECT_EQ(volume_level_dims({41, 41, 41}, 4), (std::array<int, 3>{3, 3, 3}));
  EXPECT_EQ(volume_level_dims({256, 255, 2}, 2), (std::array<int, 3>{64, 64, 2}));
  EXPECT_EQ(volume_level_dims({2, 3, 5}, 1), (std::array<int, 3>{2, 2, 3}));
  EXPECT_EQ(volume_level_dims({2, 3, 5}, 4), (std::array<int, 3>{2, 2, 2}));
  EXPECT_EQ(volume_level_dims({7, 8, 9}, 0), (std::array<int, 3>{7, 8, 9}));
}

TEST(VolumePyramid, EachRuleByHand) {
  // 4 x 3 x 2: x pairs {0,1} {2,3}; y pairs {0,1} {2}; z (2 voxels) stays.
  const std::vector<std::uint16_t> q = {0,     0,    100,  0,     // z 0, y 0
                                        0,     0,    300,  50,    //      y 1
                                        10,    20,   0,    0,     //      y 2
                                        1000,  2000, 3000, 4000,  // z 1, y 0
                                        5000,  6000, 7000, 8000,  //      y 1
                                        65535, 0,    9,    0};    //      y 2
  VolumeGrid g;
  g.dims = {4, 3, 2};
  g.values = q;
  // Coarse voxels in memory order (I fastest, then J, K), rounded to nearest.
  const std::vector<std::uint16_t> average = {0, 113, 15, 0, 3500, 5500, 32768, 5};
  const std::vector<std::uint16_t> max = {0, 300, 20, 0, 6000, 8000, 65535, 9};
  const std::vector<std::uint16_t> nonzero = {0, 150, 15, 0, 3500, 5500, 65535, 9};
  for (const auto& [how, want] :
       {std::pair{VolumePyramid::kAverage, average}, std::pair{VolumePyramid::kMax, max},
        std::pair{VolumePyramid::kNonZero, nonzero}}) {
    const auto l1 = volume_level(g, 1, how);
    EXPECT_EQ(l1->dims, (std::array<int, 3>{2, 2, 2}));
    EXPECT_EQ(l1->values, want) << static_cast<int>(how);
    // 2 x 2 x 2 cannot shrink: level 2 is level 1.
    EXPECT_EQ(volume_level(g, 2, how)->values, want);
  }
  EXPECT_EQ(volume_level(g, 0, VolumePyramid::kMax)->values, q);  // a copy
}

TEST(VolumePyramid, LevelsCompose) {
  const Volume v = procedural_volume(VolumeSourceType::kHeat, 33);
  for (VolumePyramid how :
       {VolumePyramid::kAverage, VolumePyramid::kMax, VolumePyramid::kNonZero}) {
    const auto l2 = volume_level(*v.grid, 2, how);
    const auto step = volume_level(*volume_level(*v.grid, 1, how), 1, how);
    EXPECT_EQ(l2->dims, (std::array<int, 3>{9, 9, 9}));
    EXPECT_EQ(l2->values, step->values);
  }
  // Max never falls below the average; a dense field has no zeros to skip.
  const auto avg = volume_level(*v.grid, 1, VolumePyramid::kAverage);
  const auto mx = volume_level(*v.grid, 1, VolumePyramid::kMax);
  const auto nz = volume_level(*v.grid, 1, VolumePyramid::kNonZero);
  for (std::size_t i = 0; i < avg->values.size(); ++i) EXPECT_GE(mx->values[i], avg->values[i]);
  EXPECT_EQ(nz->values, avg->values);
}

TEST(VolumeSettingsJson, DefaultsAndEveryField) {
  const Scene d = parse_scene(volume_scene(ml()), {});
  EXPECT_EQ(d.volume.samples_per_voxel, 2.0);
  EXPECT_TRUE(d.volume.opacity_correction);
  EXPECT_EQ(d.volume.ert_threshold, 0.99);
  EXPECT_EQ(d.volume.level, 0);
  EXPECT_EQ(d.volume.integration, VolumeIntegration::kPoint);
  json j = volume_scene(ml());
  j["volume"] = {{"samples_per_voxel", 0.5},
                 {"opacity_correction", false},
                 {"ert", 1},
                 {"jitter", false},
                 {"level", 4},
                 {"pyramid", "nonzero"}};
  const Scene s = parse_scene(j, {});
  EXPECT_EQ(s.volume.samples_per_voxel, 0.5);
  EXPECT_FALSE(s.volume.opacity_correction);
  EXPECT_EQ(s.volume.ert_threshold, 1.0);
  EXPECT_FALSE(s.volume.jitter);
  EXPECT_EQ(s.volume.level, 4);
  EXPECT_EQ(s.volume.pyramid, VolumePyramid::kNonZero);
  // Without opacity correction the integration stays with point samples.
  EXPECT_EQ(s.volume.integration, VolumeIntegration::kPoint);
  j["volume"] = {{"integration", "preintegrated"}};
  EXPECT_EQ(parse_scene(j, {}).volume.integration, VolumeIntegration::kPreintegrated);
  j["volume"] = {{"integration", "point"}, {"opacity_correction", false}};
  EXPECT_EQ(parse_scene(j, {}).volume.integration, VolumeIntegration::kPoint);
  // Settings without volumes are fine (a scene that adds them later by update).
  EXPECT_NO_THROW(parse_scene({{"volume", {{"level", 1}}}, {"cameras", json::array({json::object()})}}, {}));
}

TEST(VolumeSettingsJson, Refusals) {
  auto with = [](json settings) {
    json j = volume_scene(ml());
    j["volume"] = std::move(settings);
    return j;
  };
  const SceneLoadOptions o;
  EXPECT_VOLUME_ERROR(with({{"samples_per_voxel", 0}}), o, "out_of_range",
                      "/volume/samples_per_voxel");
  EXPECT_VOLUME_ERROR(with({{"samples_per_voxel", 64.5}}), o, "out_of_range",
                      "/volume/samples_per_voxel");
  EXPECT_VOLUME_ERROR(with({{"ert", 0}}), o, "out_of_range", "/volume/ert");
  EXPECT_VOLUME_ERROR(with({{"ert", 1.01}}), o, "out_of_range", "/volume/ert");
  EXPECT_VOLUME_ERROR(with({{"level", 5}}), o, "out_of_range", "/volume/level");
  EXPECT_VOLUME_ERROR(with({{"level", -1}}), o, "out_of_range", "/volume/level");
  EXPECT_VOLUME_ERROR(with({{"level", 1.5}}), o, "wrong_type", "/volume/level");
  EXPECT_VOLUME_ERROR(with({{"pyramid", "median"}}), o, "invalid_value", "/volume/pyramid");
  EXPECT_VOLUME_ERROR(with({{"jitter", 1}}), o, "wrong_type", "/volume/jitter");
  EXPECT_VOLUME_ERROR(with({{"integration", "simpson"}}), o, "invalid_value",
                      "/volume/integration");
  // The pre-integration table is made for the step's length: it needs the
  // correction.
  EXPECT_VOLUME_ERROR(with({{"integration", "preintegrated"}, {"opacity_correction", false}}), o,
                      "conflicting_fields", "/volume/integration");
  EXPECT_VOLUME_ERROR(with({{"ert_threshold", 0.9}}), o, "unknown_field", "/volume/ert_threshold");
}

TEST(VolumeJson, TransferRefusals) {
  auto with = [](json transfer) {
    json v = ml();
    v["transfer"] = std::move(transfer);
    return volume_scene(v);
  };
  const SceneLoadOptions o;
  const std::string p = "/volumes/0/transfer";
  {
    const ErrorInfo e = test::volume_error(
        with({{"points", {{0, 1, 1, 1, 0}, {0.5, 1, 1, 1, 1}, {0.4, 1, 1, 1, 1}}}}));
    EXPECT_EQ(e.code, "invalid_value");
    EXPECT_EQ(e.path, p + "/points/2/0");
    EXPECT_NE(e.message.find("point 2's value 0.4 is not above point 1's 0.5"), std::string::npos)
        << e.message;
  }
  EXPECT_VOLUME_ERROR(with({{"points", {{0, 1, 1, 1, 0}, {0, 1, 1, 1, 1}}}}), o, "invalid_value",
                      p + "/points/1/0");  // equal values: not strictly increasing
  EXPECT_VOLUME_ERROR(with({{"points", {{0, 1, 1, 1, 0}}}}), o, "invalid_value", p + "/points");
  EXPECT_VOLUME_ERROR(with({{"points", {{0, 1, 1, 1, 0}, {1.5, 1, 1, 1, 1}}}}), o, "out_of_range",
                      p + "/points/1/0");
  EXPECT_VOLUME_ERROR(with({{"points", {{0, 1, -1, 1, 0}, {1, 1, 1, 1, 1}}}}), o, "out_of_range",
                      p + "/points/0/2");
  EXPECT_VOLUME_ERROR(with({{"points", {{0, 1, 1, 1, 0}, {1, 1, 1, 1, 1.2}}}}), o, "out_of_range",
                      p + "/points/1/4");
  EXPECT_VOLUME_ERROR(with({{"points", {{0, 1, 1, 1}, {1, 1, 1, 1, 1}}}}), o, "wrong_type",
                      p + "/points/0");
  json many = json::array();
  for (int i = 0; i <= kMaxTransferPoints; ++i) many.push_back({i / 1000.0, 1, 1, 1, 0});
  EXPECT_VOLUME_ERROR(with({{"points", many}}), o, "limit_exceeded", p + "/points");
  EXPECT_VOLUME_ERROR(with({{"preset", "rainbow"}}), o, "invalid_value", p + "/preset");
  EXPECT_VOLUME_ERROR(with({{"preset", "ml"}, {"points", {{0, 1, 1, 1, 0}, {1, 1, 1, 1, 1}}}}), o,
                      "conflicting_fields", p + "/points");
  EXPECT_VOLUME_ERROR(with({{"opacity_unit", 0.5}}), o, "missing_field", p + "/points");
  EXPECT_VOLUME_ERROR(with({{"preset", "ml"}, {"opacity_unit", 0}}), o, "out_of_range",
                      p + "/opacity_unit");
  EXPECT_VOLUME_ERROR(with({{"preset", "ml"}, {"colors", 1}}), o, "unknown_field", p + "/colors");
}

TEST(VolumeJson, SourceAndPlacementRefusals) {
  const SceneLoadOptions o;
  auto with = [](std::string key, json value) {
    json v = ml();
    v[key] = std::move(value);
    return volume_scene(v);
  };
  EXPECT_VOLUME_ERROR(volume_scene(json::object()), o, "missing_field", "/volumes/0/source");
  EXPECT_VOLUME_ERROR(volume_scene({{"source", {{"type", "dicom"}}}}), o, "invalid_value",
                      "/volumes/0/source/type");
  EXPECT_VOLUME_ERROR(volume_scene({{"source", {{"type", "heat"}, {"file", "x.raw"}}}}), o,
                      "unknown_field", "/volumes/0/source/file");
  EXPECT_VOLUME_ERROR(volume_scene({{"source", {{"type", "nrrd"}, {"resolution", 3}}}}), o,
                      "unknown_field", "/volumes/0/source/resolution");
  EXPECT_VOLUME_ERROR(with("range", {0.5, 0.5}), o, "invalid_value", "/volumes/0/range");
  EXPECT_VOLUME_ERROR(with("range", {1, 0}), o, "invalid_value", "/volumes/0/range");
  EXPECT_VOLUME_ERROR(with("range", {-1e308, 1e308}), o, "invalid_value", "/volumes/0/range");
  EXPECT_VOLUME_ERROR(with("rotation", {0, 0, 0, 0}), o, "invalid_value", "/volumes/0/rotation");
  EXPECT_VOLUME_ERROR(with("spacing", 0), o, "out_of_range", "/volumes/0/spacing");
  EXPECT_VOLUME_ERROR(with("spacing", {1, -1, 1}), o, "out_of_range", "/volumes/0/spacing/1");
  // 5 voxels 6e11 apart: the box reaches +-1.2e12, beyond max_abs_coordinate.
  EXPECT_VOLUME_ERROR(with("spacing", 6e11), o, "out_of_range", "/volumes/0/spacing");
  EXPECT_VOLUME_ERROR(with("origin", {0, 2e12, 0}), o, "out_of_range", "/volumes/0/origin/1");
  EXPECT_VOLUME_ERROR(with("intensity", 0), o, "out_of_range", "/volumes/0/intensity");
  EXPECT_VOLUME_ERROR(with("colour", 1), o, "unknown_field", "/volumes/0/colour");
  json nine = volume_scene(ml(2));
  for (int i = 0; i < kMaxVolumes; ++i) nine["volumes"].push_back(ml(2));
  EXPECT_VOLUME_ERROR(nine, o, "limit_exceeded", "/volumes");
}

TEST(VolumeJson, ResolutionLimits) {
  const SceneLoadOptions o;
  const std::string p = "/volumes/0/source/resolution";
  EXPECT_VOLUME_ERROR(volume_scene(ml(1)), o, "out_of_range", p);
  EXPECT_VOLUME_ERROR(volume_scene(ml(0)), o, "out_of_range", p);
  // 1000^3 voxels: over max_volume_voxels (checked before anything is allocated).
  EXPECT_VOLUME_ERROR(volume_scene(ml(1000)), o, "limit_exceeded", p);
  // 2^40 cubed overflows 64 bits: refused as such, not wrapped around.
  const ErrorInfo e =
      test::volume_error(volume_scene({{"source", {{"type", "heat"}, {"resolution", 1LL << 40}}}}));
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_EQ(e.path, p);
  EXPECT_NE(e.message.find("64-bit"), std::string::npos) << e.message;
  EXPECT_VOLUME_ERROR(volume_scene({{"source", {{"type", "heat"}, {"resolution", 2.5}}}}), o,
                      "wrong_type", p);
}

TEST(VolumeJson, Capabilities) {
  const json caps = scene_capabilities();
  EXPECT_EQ(caps["volume_source_types"], json({"raw", "nrrd", "inr", "metaimage", "marschner_lobb", "heat"}));
  EXPECT_EQ(caps["volume_sources"]["raw"], json({"file", "dimensions", "format", "endian"}));
  EXPECT_EQ(caps["volume_transfer_presets"], json({"grey", "bone", "ml"}));
  EXPECT_EQ(caps["volume_pyramids"], json({"average", "max", "nonzero"}));
  EXPECT_EQ(caps["volume_integrations"], json({"point", "preintegrated"}));
  // Numbers are hello's limits (server/settings.cpp), not capabilities.
  EXPECT_FALSE(caps.contains("volume_limits"));
  EXPECT_EQ(caps["volume_settings"].size(), std::size(kVolumeSettingFields));
}

}  // namespace
}  // namespace beamcast
