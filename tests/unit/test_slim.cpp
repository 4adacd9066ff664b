// SLIM surfaces (issue 16): the model's geometry (heights, creases,
// transforms), the CPU reference's ray casting of the blended function F on
// shapes with a known answer, the scene format with its errors, and the
// model files (JSON and binary).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>

#include "protocol/errors.hpp"
#include "protocol/scene_json.hpp"
#include "protocol/slim_io.hpp"
#include "protocol/slim_model.hpp"
#include "render/slim_compare.hpp"
#include "slim/test_shapes.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

double angle_deg(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(dot(normalize(a), normalize(b)), -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

TEST(SlimModel, AFlatSupportIsItsPlane) {
  std::vector<SlimSphere> spheres(1);
  spheres[0].radius = 1.0;  // centre 0, identity frame, w = 0: the plane z = 0
  const SlimField field(&spheres);
  const auto hit = field.intersect({0.2, 0.1, 3.0}, {0.0, 0.0, -1.0}, 0.0, 10.0);
  ASSERT_TRUE(hit.has_value());
  // Bisection to 1e-12 of the radius.
  EXPECT_NEAR(hit->t, 3.0, 1e-9);
  EXPECT_LT(angle_deg(hit->n, {0.0, 0.0, 1.0}), 1e-3);
  // Outside the support there is no surface.
  EXPECT_FALSE(field.intersect({1.2, 0.0, 3.0}, {0.0, 0.0, -1.0}, 0.0, 10.0).has_value());
  // F grows along the normal: positive above, negative below.
  EXPECT_GT(field.value({0.0, 0.0, 0.1}).f, 0.0);
  EXPECT_LT(field.value({0.0, 0.0, -0.1}).f, 0.0);
}

TEST(SlimModel, ACreaseTakesTheMinOfItsTwoPolynomials) {
  SlimSphere s;
  s.radius = 1.0;
  s.poly.c = {0, 0, 0, 1, 0, 0};    // w = u
  s.poly2.c = {0, 0, 0, -1, 0, 0};  // w = -u
  s.crease = SlimCrease::kMin;      // w = -|u|: a ridge along v
  EXPECT_DOUBLE_EQ(s.height(0.3, 0.2), -0.3);
  EXPECT_DOUBLE_EQ(s.height(-0.3, 0.2), -0.3);
  EXPECT_EQ(s.height_grad(0.3, 0.0), (std::array<double, 2>{-1.0, 0.0}));
  EXPECT_EQ(s.height_grad(-0.3, 0.0), (std::array<double, 2>{1.0, 0.0}));
  s.crease = SlimCrease::kMax;  // w = |u|: a valley
  EXPECT_DOUBLE_EQ(s.height(-0.3, 0.2), 0.3);
  s.crease = SlimCrease::kMin;
  const std::vector<SlimSphere> spheres{s};
  const SlimField field(&spheres);
  const auto hit = field.intersect({0.3, 0.0, 3.0}, {0.0, 0.0, -1.0}, 0.0, 10.0);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->t, 3.3, 1e-9);
  // The ridge's face u > 0 has normal (1, 0, 1) / sqrt 2.
  EXPECT_LT(angle_deg(hit->n, {1.0, 0.0, 1.0}), 1e-3);
}

// 400 supports of 2x the lattice spacing on the unit sphere: each
// paraboloid is off the sphere by at most rho^4 / 8 = 0.0019 at its rim
// (rho = 0.354), and F blends values between the supports' own, so the
// zero set lies within 0.0019 of the sphere; 3e-3 allows the bisection and
// the blend's small tilt. Normals: the paraboloids' slopes differ from the
// sphere's by rho^3 / (2 R^3) ~ 0.022 rad at a rim: 2 degrees.
TEST(SlimModel, AGeneratedSphereLiesOnTheSphere) {
  const Vec3 c{0.5, -0.25, 1.0};
  const auto spheres = test::slim_sphere(c, 1.0, 400);
  const SlimField field(&spheres);
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  double worst_t = 0.0, worst_deg = 0.0;
  for (int i = 0; i < 64; ++i) {
    const Vec3 dir = normalize(Vec3{g(rng), g(rng), g(rng)});
    const auto hit = field.intersect(c + 5.0 * dir, -1.0 * dir, 0.0, 10.0);
    ASSERT_TRUE(hit.has_value()) << i;
    worst_t = std::max(worst_t, std::abs(hit->t - 4.0));
    worst_deg = std::max(worst_deg, angle_deg(hit->n, dir));
  }
  EXPECT_LT(worst_t, 3e-3);
  EXPECT_LT(worst_deg, 2.0);
}

TEST(SlimModel, TransformsMoveTheSurfacePointsRigidlyAndScaleThem) {
  SlimSphere s;
  s.center = {0.3, -0.2, 0.5};
  s.radius = 0.7;
  s.rotation = quat_from_axes(normalize(Vec3{1, 1, 0}), normalize(Vec3{-1, 1, 0}), {0, 0, 1});
  s.poly.c = {0.4, -0.3, 0.2, 0.1, -0.5, 0.05};
  std::vector<SlimSphere> moved{s};
  const Vec3 t{1.0, 2.0, -3.0};
  const double k = 2.5;
  const std::array<double, 4> q{std::cos(0.4), std::sin(0.4) * 0.6, 0.0, std::sin(0.4) * 0.8};
  transform_slim(moved, t, k, q);
  EXPECT_DOUBLE_EQ(moved[0].radius, k * s.radius);
  // rotate(q, x) as the rotation of quat_from_axes' frame: compare through
  // a sphere with centre 0 and frame q.
  SlimSphere frame;
  frame.rotation = q;
  for (double u : {-0.5, 0.0, 0.3}) {
    for (double v : {-0.2, 0.4}) {
      const Vec3 want = t + k * frame.to_world(s.surface_point(u, v));
      const Vec3 got = moved[0].surface_point(k * u, k * v);
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i], want[i], 1e-12) << u << " " << v;
      EXPECT_LT(angle_deg(moved[0].surface_normal(k * u, k * v), frame.to_world(s.surface_normal(u, v))),
                1e-6);
    }
  }
}

// The supersampled reference averages depth and normal over the pixel: on a
// tilted plane seen by an orthographic camera the view depth is linear in
// the window, so the 4 x 4 mean equals the centre's; the normal is the
// plane's either way. Coverage comes from the centre ray in both.
TEST(SlimReference, SupersampledDepthIsThePixelMeanOnAPlane) {
  Scene scene;
  std::vector<SlimSphere> spheres(1);
  spheres[0].radius = 3.0;
  spheres[0].rotation =
      quat_from_axes({1, 0, 0}, normalize(Vec3{0, 1, 1}), normalize(Vec3{0, -1, 1}));
  scene.occluders.push_back(Occluder{SlimOccluder::from_spheres(spheres), {0.5, 0.5, 0.5}, {}});
  Camera cam;
  cam.projection = Projection::kOrthographic;
  cam.ortho_height = 2.0;
  cam.position = {0.0, 0.0, 5.0};
  cam.target = Vec3{0.0, 0.0, 0.0};
  cam.width = cam.height = 16;
  const SlimPixels one = slim_reference(scene, cam, 1, 1);
  const SlimPixels many = slim_reference(scene, cam, 1, 4);
  EXPECT_EQ(one.covered, many.covered);
  int covered = 0;
  for (std::size_t i = 0; i < one.covered.size(); ++i) {
    if (!one.covered[i]) continue;
    ++covered;
    EXPECT_NEAR(many.depth[i], one.depth[i], 1e-5) << i;
    EXPECT_LT(angle_deg(many.normal[i], normalize(Vec3{0, -1, 1})), 1e-4) << i;
  }
  EXPECT_EQ(covered, 256);
  // On a sphere the depth is not linear across a pixel: the means differ
  // from the centres (the sub-rays do sample the pixel's area).
  Scene round;
  round.occluders.push_back(Occluder{
      SlimOccluder::from_spheres(test::slim_sphere({0, 0, 0}, 1.0, 400)), {0.5, 0.5, 0.5}, {}});
  cam.ortho_height = 2.4;
  const SlimPixels c1 = slim_reference(round, cam, 1, 1);
  const SlimPixels c4 = slim_reference(round, cam, 1, 4);
  int differ = 0, hits = 0;
  for (std::size_t i = 0; i < c1.covered.size(); ++i) {
    if (!c1.covered[i]) continue;
    ++hits;
    if (std::abs(c4.depth[i] - c1.depth[i]) > 1e-4) ++differ;
  }
  EXPECT_GT(differ, hits / 2);
}

// ---- The scene format -------------------------------------------------------------

json slim_scene(json occluder) {
  return {{"occluders", json::array({std::move(occluder)})},
          {"cameras", {{{"position", {0, 0, 5}}, {"target", {0, 0, 0}}}}}};
}

json one_sphere(json extra = json::object()) {
  json s = {{"center", {0, 0, 0}}, {"radius", 1.0}, {"coefficients", {0, 0, 0, 0, 0, 0}}};
  s.update(extra);
  return s;
}

ErrorInfo error_of(const json& j, const SceneLoadOptions& opts = {}) {
  try {
    parse_scene(j, opts);
  } catch (const ProtocolError& e) {
    return e.info();
  }
  ADD_FAILURE() << "scene was accepted: " << j.dump();
  return {};
}

#define EXPECT_REJECTED(scene, want_code, want_path, ...)                 \
  do {                                                                    \
    const ErrorInfo info_ = error_of((scene)__VA_OPT__(, ) __VA_ARGS__);  \
    EXPECT_EQ(info_.code, (want_code)) << info_.message;                  \
    EXPECT_EQ(info_.path, (want_path)) << info_.message;                  \
    EXPECT_FALSE(info_.message.empty());                                  \
  } while (0)

TEST(SlimFormat, InlineSpheresParseAndArePlaced) {
  const json j = slim_scene({{"type", "slim"},
                             {"spheres", {one_sphere({{"rotation", {2, 0, 0, 0}}}),
                                          one_sphere({{"center", {1, 0, 0}},
                                                      {"coefficients2", {0, 0, 0, 1, 0, 0}},
                                                      {"crease", "max"}})}},
                             {"translate", {0, 1, 0}},
                             {"scale", 2},
                             {"material", {{"type", "diffuse"}, {"albedo", {0.5, 0.5, 0.5}}}}});
  const Scene scene = parse_scene(j, {});
  ASSERT_EQ(scene.occluders.size(), 1u);
  const auto& slim = std::get<SlimOccluder>(scene.occluders[0].shape);
  ASSERT_EQ(slim.spheres().size(), 2u);
  EXPECT_EQ(slim.spheres()[0].rotation, (std::array<double, 4>{1, 0, 0, 0}));  // normalized
  EXPECT_EQ(slim.spheres()[1].center, (Vec3{2, 1, 0}));
  EXPECT_DOUBLE_EQ(slim.spheres()[1].radius, 2.0);
  EXPECT_EQ(slim.spheres()[1].crease, SlimCrease::kMax);
  EXPECT_TRUE(slim.file.empty());
  // The occluder is hit where its plane z = 0 lies.
  const auto hit = slim.intersect({0.0, 1.0, 5.0}, {0.0, 0.0, -1.0}, 0.0, 10.0);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->t, 5.0, 1e-9);
}

TEST(SlimFormat, BadFieldsAreRefusedWithTheirPath) {
  auto with = [](json sphere) { return slim_scene({{"type", "slim"}, {"spheres", json::array({std::move(sphere)})}}); };
  EXPECT_REJECTED(with(one_sphere({{"radius", -1}})), "out_of_range", "/occluders/0/spheres/0/radius");
  EXPECT_REJECTED(with(one_sphere({{"coefficients", {0, 0, 0, 0, 0, 1e13}}})), "out_of_range",
                  "/occluders/0/spheres/0/coefficients");
  EXPECT_EQ(error_of(with(one_sphere({{"coefficients", {0, 0, 0, 0, 0}}}))).path,
            "/occluders/0/spheres/0/coefficients");
  EXPECT_REJECTED(with(one_sphere({{"crease", "min"}})), "invalid_value", "/occluders/0/spheres/0/crease");
  EXPECT_REJECTED(with(one_sphere({{"coefficients2", {0, 0, 0, 0, 0, 0}}, {"crease", "mean"}})),
                  "invalid_value", "/occluders/0/spheres/0/crease");
  EXPECT_REJECTED(with(one_sphere({{"rotation", {0, 0, 0, 0}}})), "invalid_value",
                  "/occluders/0/spheres/0/rotation");
  EXPECT_REJECTED(with(one_sphere({{"colour", 1}})), "unknown_field", "/occluders/0/spheres/0/colour");
  EXPECT_REJECTED(slim_scene({{"type", "slim"}, {"spheres", json::array()}}), "invalid_value",
                  "/occluders/0/spheres");
  EXPECT_REJECTED(slim_scene({{"type", "slim"}}), "missing_field", "/occluders/0/spheres");
  EXPECT_REJECTED(slim_scene({{"type", "slim"}, {"spheres", json::array({one_sphere()})}, {"file", "a.slim"}}),
                  "invalid_value", "/occluders/0/spheres");
  EXPECT_REJECTED(slim_scene({{"type", "slim"}, {"spheres", json::array({one_sphere()})}, {"scale", 0}}),
                  "out_of_range", "/occluders/0/scale");
  json settings = slim_scene({{"type", "slim"}, {"spheres", json::array({one_sphere()})}});
  settings["slim"] = {{"sampling", 0.1}};
  EXPECT_REJECTED(settings, "out_of_range", "/slim/sampling");
  settings["slim"] = {{"cull_backfaces", 1}};
  EXPECT_REJECTED(settings, "wrong_type", "/slim/cull_backfaces");
  settings["slim"] = {{"holes", true}};
  EXPECT_REJECTED(settings, "unknown_field", "/slim/holes");
}

// hello lists the kind and the settings the parser accepts (each of them
// parses; a field not listed is refused above).
TEST(SlimFormat, HelloListsTheKindAndTheSettings) {
  const json caps = scene_capabilities();
  const auto& types = caps.at("occluder_types");
  EXPECT_NE(std::find(types.begin(), types.end(), "slim"), types.end());
  json scene = slim_scene({{"type", "slim"}, {"spheres", json::array({one_sphere()})}});
  scene["slim"] = json::object();
  for (const auto& field : caps.at("slim_settings")) {
    const std::string name = field.get<std::string>();
    scene["slim"][name] = name == "sampling"          ? json(3.0)
                          : name == "depth_threshold" ? json(0.5)
                          : name == "evaluation"      ? json("blend")
                                                      : json(false);
  }
  EXPECT_EQ(caps.at("slim_settings").size(), 5u);
  const Scene parsed = parse_scene(scene, {});
  EXPECT_EQ(parsed.slim.sampling, 3.0);
  EXPECT_EQ(parsed.slim.depth_threshold, 0.5);
  EXPECT_FALSE(parsed.slim.fill_holes);
  EXPECT_FALSE(parsed.slim.cull_backfaces);
  EXPECT_EQ(parsed.slim.evaluation, SlimEvaluation::kBlend);
  EXPECT_EQ(
      parse_scene(slim_scene({{"type", "slim"}, {"spheres", json::array({one_sphere()})}}), {}).slim.evaluation,
      SlimEvaluation::kPatch);
  scene["slim"]["evaluation"] = "field";
  EXPECT_EQ(parse_scene(scene, {}).slim.evaluation, SlimEvaluation::kField);
  scene["slim"]["evaluation"] = "patch";
  EXPECT_EQ(parse_scene(scene, {}).slim.evaluation, SlimEvaluation::kPatch);
  scene["slim"]["evaluation"] = "exact";
  EXPECT_REJECTED(scene, "invalid_value", "/slim/evaluation");
}

TEST(SlimFormat, TheSphereCountIsLimitedOverTheScene) {
  SceneLoadOptions opts;
  opts.limits.max_slim_spheres = 3;
  json j = slim_scene({{"type", "slim"}, {"spheres", {one_sphere(), one_sphere()}}});
  EXPECT_NO_THROW(parse_scene(j, opts));
  j["occluders"].push_back({{"type", "slim"}, {"spheres", {one_sphere(), one_sphere()}}});
  EXPECT_REJECTED(j, "limit_exceeded", "/occluders/1/spheres", opts);
}

class SlimFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("beamcast_slim_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            std::to_string(reinterpret_cast<std::uintptr_t>(this)));
    std::filesystem::create_directories(dir_);
    opts_.assets_dir = dir_;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  void write(const std::string& name, const std::string& bytes) {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
  }
  std::filesystem::path dir_;
  SceneLoadOptions opts_;
};

TEST_F(SlimFiles, JsonAndBinaryFormsRoundTrip) {
  const auto spheres = test::slim_torus({0, 0, 0}, 2.0, 0.5, 24, 8);
  write_slim_file(dir_ / "torus.json", spheres);
  write_slim_file(dir_ / "torus.bslm", spheres);
  EXPECT_EQ(std::filesystem::file_size(dir_ / "torus.bslm"), 16u + 84u * spheres.size());
  for (const char* name : {"torus.json", "torus.bslm"}) {
    const Scene s = parse_scene(slim_scene({{"type", "slim"}, {"file", name}}), opts_);
    const auto& slim = std::get<SlimOccluder>(s.occluders[0].shape);
    EXPECT_EQ(slim.file, name);
    ASSERT_EQ(slim.spheres().size(), spheres.size());
    // JSON keeps doubles; binary keeps floats (relative 6e-8, x 2 for the
    // rotation's renormalization).
    const double tol = std::string(name).ends_with(".json") ? 1e-15 : 2e-7;
    for (std::size_t i = 0; i < spheres.size(); ++i) {
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(slim.spheres()[i].center[k], spheres[i].center[k], tol * 3);
      for (int k = 0; k < 6; ++k) EXPECT_NEAR(slim.spheres()[i].poly.c[k], spheres[i].poly.c[k], tol * 4);
      for (int k = 0; k < 4; ++k) EXPECT_NEAR(slim.spheres()[i].rotation[k], spheres[i].rotation[k], tol);
    }
  }
}

TEST_F(SlimFiles, BadFilesAreRefusedAtTheFileField) {
  const auto spheres = test::slim_sphere({0, 0, 0}, 1.0, 20);
  std::string bin = slim_to_binary(spheres);
  write("cut.bslm", bin.substr(0, bin.size() - 3));
  write("nan.bslm", [&] {
    std::string b = bin;
    const float nan = std::nanf("");
    std::memcpy(b.data() + 16 + 84 * 5 + 12, &nan, 4);  // sphere 5's radius
    return b;
  }());
  json bad = slim_to_json(spheres);
  bad["spheres"][3]["radius"] = -2;
  write("bad.json", bad.dump());
  write("text.json", "not a model");
  auto scene = [](const std::string& f) { return slim_scene({{"type", "slim"}, {"file", f}}); };
  EXPECT_REJECTED(scene("cut.bslm"), "bad_slim", "/occluders/0/file", opts_);
  EXPECT_REJECTED(scene("nan.bslm"), "bad_slim", "/occluders/0/file", opts_);
  EXPECT_NE(error_of(scene("nan.bslm"), opts_).message.find("sphere 5"), std::string::npos);
  EXPECT_REJECTED(scene("bad.json"), "bad_slim", "/occluders/0/file", opts_);
  EXPECT_NE(error_of(scene("bad.json"), opts_).message.find("/spheres/3/radius"), std::string::npos);
  EXPECT_REJECTED(scene("text.json"), "bad_slim", "/occluders/0/file", opts_);
  EXPECT_REJECTED(scene("none.bslm"), "file_not_found", "/occluders/0/file", opts_);
  EXPECT_REJECTED(scene("../x.bslm"), "forbidden_path", "/occluders/0/file", opts_);
  SceneLoadOptions small = opts_;
  small.limits.max_slim_spheres = 10;
  write("ok.bslm", bin);
  EXPECT_REJECTED(scene("ok.bslm"), "limit_exceeded", "/occluders/0/file", small);
}

}  // namespace
}  // namespace beamcast

namespace beamcast {
namespace {

// slim_height_range bounds the height of every point of a patch that lies
// inside its sphere (the GPU's patch proxy relies on it: a point outside
// the bound would be a hole). Checked on strongly curved and creased
// patches, tilted ones and ones that leave the sphere early, against
// 400 x 400 samples of the patch (a 12x finer grid than the bound's own).
TEST(SlimModel, TheHeightRangeHoldsThePatchInsideTheSphere) {
  int checked = 0, narrower = 0;
  for (int k = 0; k < 40; ++k) {
    SlimSphere s;
    s.radius = 0.5 + 0.1 * k;
    const double a = std::sin(1.3 * k), b = std::cos(0.7 * k), c = std::sin(2.1 * k + 0.4);
    s.poly.c = {2.0 * a / s.radius, 0.8 * b / s.radius, 1.5 * c / s.radius, 0.9 * b, -0.6 * a,
                0.3 * c * s.radius};
    if (k % 3 == 1) {
      s.crease = k % 2 == 0 ? SlimCrease::kMin : SlimCrease::kMax;
      s.poly2.c = {-a / s.radius, 0.2, 0.5 * b / s.radius, -0.9 * c, 0.4, -0.2 * s.radius};
    }
    const auto range = slim_height_range(s);
    const double r = s.radius;
    double lo = 1e300, hi = -1e300;
    constexpr int kN = 400;
    for (int i = 0; i < kN; ++i) {
      for (int j = 0; j < kN; ++j) {
        const double u = -r + 2.0 * r * (i + 0.5) / kN, v = -r + 2.0 * r * (j + 0.5) / kN;
        const double w = s.height(u, v);
        if (u * u + v * v + w * w >= r * r) continue;
        lo = std::min(lo, w);
        hi = std::max(hi, w);
        ++checked;
      }
    }
    if (lo > hi) continue;
    EXPECT_LE(range[0], lo) << k;
    EXPECT_GE(range[1], hi) << k;
    if (range[1] - range[0] < 1.9 * r) ++narrower;
  }
  EXPECT_GT(checked, 100000);
  // And it is a bound worth having: most of these patches' slabs are
  // narrower than the sphere.
  EXPECT_GT(narrower, 20);
}

}  // namespace
}  // namespace beamcast
