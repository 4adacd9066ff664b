// Scene JSON parsing and validation: every rejection class checks code and JSON
// pointer; positive tests check values and defaults.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>
#include <string>

#include "protocol/scene_json.hpp"

namespace beamcast {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

const fs::path kSourceDir = BEAMCAST_SOURCE_DIR;
const fs::path kDataDir = kSourceDir / "tests" / "data";

json minimal() { return json::parse(R"({"cameras": [{}]})"); }

// A scene with one beam of each kind, one occluder and one camera, all valid.
json base() {
  return json::parse(R"({
    "beams": [
      {"type": "sphere", "center": [0, 0, 0], "radius": 1},
      {"type": "capsule", "p0": [0, 0, 0], "p1": [3, 0, 0], "radius": 0.5}
    ],
    "occluders": [{"type": "box", "center": [0, -2, 0], "size": [4, 0.1, 4]}],
    "cameras": [{"name": "main", "position": [0, 0, 5], "target": [0, 0, 0]}]
  })");
}

json with(json j, const std::string& pointer, json value) {
  j[json::json_pointer(pointer)] = std::move(value);
  return j;
}

json without(json j, const std::string& parent, const std::string& key) {
  j[json::json_pointer(parent)].erase(key);
  return j;
}

SceneLoadOptions data_opts() {
  SceneLoadOptions o;
  o.assets_dir = kDataDir;
  return o;
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

#define EXPECT_REJECTED(scene, opts, want_code, want_path) \
  do {                                                     \
    const ErrorInfo info_ = error_of((scene), (opts));     \
    EXPECT_EQ(info_.code, (want_code)) << info_.message;   \
    EXPECT_EQ(info_.path, (want_path)) << info_.message;   \
    EXPECT_FALSE(info_.message.empty());                   \
  } while (0)

json mesh_scene(const std::string& file) {
  return with(minimal(), "/occluders", json::array({{{"type", "mesh"}, {"file", file}}}));
}

// ---- Positive ---------------------------------------------------------------------

TEST(SceneJson, BaseSceneIsAccepted) { EXPECT_NO_THROW(parse_scene(base(), {})); }

TEST(SceneJson, DefaultsApplied) {
  const Scene s = parse_scene(json::parse(R"({"beams": [{"type": "sphere", "center": [1, 2, 3],
      "radius": 2}], "cameras": [{}]})"),
                              {});
  const Scene d;  // the model's defaults
  EXPECT_EQ(s.background, d.background);
  EXPECT_EQ(s.light.direction, d.light.direction);
  EXPECT_EQ(s.light.ambient, d.light.ambient);
  EXPECT_EQ(s.output.tone, ToneCurve::kExponential);
  EXPECT_EQ(s.output.bit_depth, 8);
  EXPECT_EQ(s.render.table_d, 128);
  EXPECT_EQ(s.render.f_table, 1024);
  ASSERT_EQ(s.beams.size(), 1u);
  const Beam& b = s.beams[0];
  EXPECT_EQ(b.color, (Color{1, 1, 1}));
  EXPECT_EQ(b.intensity, 1.0);
  EXPECT_EQ(b.density.kind, DensityKind::kLinear);
  EXPECT_EQ(std::get<SphereBeam>(b.shape).center, (Vec3{1, 2, 3}));
  ASSERT_EQ(s.cameras.size(), 1u);
  const Camera& c = s.cameras[0];
  EXPECT_EQ(c.position, (Vec3{0, 0, 5}));
  EXPECT_FALSE(c.target.has_value());
  EXPECT_FALSE(c.rotation.has_value());
  EXPECT_EQ(c.projection, Projection::kPerspective);
  EXPECT_EQ(c.fov_y_deg, 45.0);
  EXPECT_EQ(c.width, 512);
  EXPECT_EQ(c.height, 512);
  EXPECT_TRUE(c.name.empty());
}

TEST(SceneJson, FullSceneRoundTrip) {
  const json j = json::parse(R"({
    "version": 1,
    "background": [0.01, 0.02, 0.03],
    "light": {"direction": [0, -1, 0], "color": [1, 0.9, 0.8], "intensity": 2, "ambient": 0.25},
    "beams": [
      {"type": "sphere", "center": [0, 0, 0], "radius": 1.5, "color": [0.2, 0.5, 1],
       "intensity": 3, "density": "abe"},
      {"type": "capsule", "p0": [0, 0, 0], "p1": [0, 0, -10], "caps": [false, true],
       "radius": 0.5, "density": {"type": "gaussian", "sigma": 0.3}},
      {"type": "sphere", "center": [5, 0, 0], "radius": 1,
       "density": {"type": "table", "samples": [1, 0.5, 0]}},
      {"type": "sphere", "center": [6, 0, 0], "radius": 1, "density": {"type": "shell"}}
    ],
    "occluders": [
      {"type": "plane", "point": [0, -3, 0], "normal": [0, 2, 0], "albedo": [0.5, 0.5, 0.5]},
      {"type": "box", "center": [1, 2, 3], "size": [1, 2, 3], "rotation": [2, 0, 0, 0]},
      {"type": "sphere", "center": [0, 0, -20], "radius": 4}
    ],
    "cameras": [
      {"name": "front", "position": [0, 0, 10], "target": [0, 0, 0], "up": [0, 1, 0],
       "fov_y": 60, "near": 0.1, "far": 100, "width": 640, "height": 480},
      {"name": "top.ortho-2", "position": [0, 10, 0], "rotation": [0.7071067811865476, -0.7071067811865476, 0, 0],
       "projection": "orthographic", "ortho_height": 12, "width": 256, "height": 256}
    ],
    "output": {"exposure": 0.5, "tone": "reinhard", "bit_depth": 16},
    "render": {"table_size": [64, 256], "f_table": 4096}
  })");
  const Scene s = parse_scene(j, {});
  EXPECT_EQ(s.background, (Color{0.01, 0.02, 0.03}));
  EXPECT_EQ(s.light.direction, (Vec3{0, -1, 0}));
  EXPECT_EQ(s.light.color, (Color{1, 0.9, 0.8}));
  EXPECT_EQ(s.light.intensity, 2.0);
  EXPECT_EQ(s.light.ambient, 0.25);

  ASSERT_EQ(s.beams.size(), 4u);
  EXPECT_EQ(s.beams[0].radius, 1.5);
  EXPECT_EQ(s.beams[0].color, (Color{0.2, 0.5, 1}));
  EXPECT_EQ(s.beams[0].intensity, 3.0);
  EXPECT_EQ(s.beams[0].density.kind, DensityKind::kAbe);
  const auto& cap = std::get<CapsuleBeam>(s.beams[1].shape);
  EXPECT_EQ(cap.p1, (Vec3{0, 0, -10}));
  EXPECT_FALSE(cap.cap0);
  EXPECT_TRUE(cap.cap1);
  EXPECT_EQ(s.beams[1].density.kind, DensityKind::kGaussian);
  EXPECT_EQ(s.beams[1].density.sigma, 0.3);
  EXPECT_EQ(s.beams[2].density.kind, DensityKind::kTable);
  EXPECT_EQ(s.beams[2].density.samples, (std::vector<double>{1, 0.5, 0}));
  EXPECT_EQ(s.beams[3].density.kind, DensityKind::kShell);

  ASSERT_EQ(s.occluders.size(), 3u);
  EXPECT_EQ(std::get<PlaneOccluder>(s.occluders[0].shape).normal, (Vec3{0, 2, 0}));
  EXPECT_EQ(s.occluders[0].albedo, (Color{0.5, 0.5, 0.5}));
  const auto& box = std::get<BoxOccluder>(s.occluders[1].shape);
  EXPECT_EQ(box.size, (Vec3{1, 2, 3}));
  EXPECT_EQ(box.rotation, (std::array<double, 4>{1, 0, 0, 0}));  // normalized
  EXPECT_EQ(s.occluders[1].albedo, (Color{0.8, 0.8, 0.8}));
  EXPECT_EQ(std::get<SphereOccluder>(s.occluders[2].shape).radius, 4.0);

  ASSERT_EQ(s.cameras.size(), 2u);
  EXPECT_EQ(s.cameras[0].name, "front");
  EXPECT_EQ(*s.cameras[0].target, (Vec3{0, 0, 0}));
  EXPECT_EQ(s.cameras[0].fov_y_deg, 60.0);
  EXPECT_EQ(s.cameras[0].near_plane, 0.1);
  EXPECT_EQ(s.cameras[0].far_plane, 100.0);
  EXPECT_EQ(s.cameras[0].width, 640);
  EXPECT_EQ(s.cameras[0].height, 480);
  EXPECT_EQ(s.cameras[1].projection, Projection::kOrthographic);
  EXPECT_EQ(s.cameras[1].ortho_height, 12.0);
  ASSERT_TRUE(s.cameras[1].rotation.has_value());
  EXPECT_NEAR((*s.cameras[1].rotation)[0], std::sqrt(0.5), 1e-15);

  EXPECT_EQ(s.output.exposure, 0.5);
  EXPECT_EQ(s.output.tone, ToneCurve::kReinhard);
  EXPECT_EQ(s.output.bit_depth, 16);
  EXPECT_EQ(s.render.table_d, 64);
  EXPECT_EQ(s.render.table_s, 256);
  EXPECT_EQ(s.render.f_table, 4096);
}

TEST(SceneJson, ScalarTableSizeSetsBothAxes) {
  const Scene s = parse_scene(with(minimal(), "/render", {{"table_size", 32}}), {});
  EXPECT_EQ(s.render.table_d, 32);
  EXPECT_EQ(s.render.table_s, 32);
}

// output.supersample: k in [1, 4]; the camera at k times its size within
// the frame-size limits, the error at the knob (its default 1 adds nothing).
TEST(SceneJson, SupersampleIsCheckedAgainstTheFrameLimits) {
  EXPECT_EQ(parse_scene(minimal(), {}).output.supersample, 1);
  const json wide = with(minimal(), "/cameras/0", {{"width", 4096}, {"height", 256}});
  EXPECT_EQ(parse_scene(with(wide, "/output", {{"supersample", 2}}), {}).output.supersample, 2);
  for (const int bad : {0, 5}) {
    const ErrorInfo e = error_of(with(minimal(), "/output", {{"supersample", bad}}));
    EXPECT_EQ(e.code, "out_of_range");
    EXPECT_EQ(e.path, "/output/supersample");
  }
  // 3 x 4096 = 12288 > max_width 8192.
  const ErrorInfo e = error_of(with(wide, "/output", {{"supersample", 3}}));
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_EQ(e.path, "/output/supersample");
  EXPECT_NE(e.message.find("12288"), std::string::npos) << e.message;
}

TEST(SceneJson, NearParallelRule) {
  EXPECT_EQ(parse_scene(minimal(), {}).render.near_parallel, NearParallel::kQuadrature);
  const Scene s = parse_scene(with(minimal(), "/render", {{"near_parallel", "none"}}), {});
  EXPECT_EQ(s.render.near_parallel, NearParallel::kNone);
  EXPECT_REJECTED(with(minimal(), "/render", {{"near_parallel", "midpoint"}}), SceneLoadOptions{},
                  "invalid_value", "/render/near_parallel");
}

TEST(SceneJson, IntegralFloatAcceptedAsInteger) {
  const Scene s = parse_scene(with(minimal(), "/cameras/0/width", 320.0), {});
  EXPECT_EQ(s.cameras[0].width, 320);
}

TEST(SceneJson, ParseCameraUsesGivenPath) {
  try {
    parse_camera(json::parse(R"({"fov_y": 180})"), "/poses/7", SceneLimits{});
    FAIL() << "accepted";
  } catch (const ProtocolError& e) {
    EXPECT_EQ(e.info().code, "out_of_range");
    EXPECT_EQ(e.info().path, "/poses/7/fov_y");
  }
}

// ---- Meshes -----------------------------------------------------------------------

TEST(SceneJsonMesh, TetrahedronTransformed) {
  json j = mesh_scene("tetrahedron.obj");
  j["occluders"][0]["translate"] = {10, 0, 0};
  j["occluders"][0]["scale"] = 2;
  j["occluders"][0]["rotation"] = {std::sqrt(0.5), 0, 0, std::sqrt(0.5)};  // 90 deg about +Z
  const Scene s = parse_scene(j, data_opts());
  const auto& m = std::get<MeshOccluder>(s.occluders[0].shape);
  EXPECT_EQ(m.file, "tetrahedron.obj");
  ASSERT_EQ(m.vertices.size(), 4u);
  ASSERT_EQ(m.triangles.size(), 4u);
  // v2 = (1, 0, 0): scaled to (2, 0, 0), rotated to (0, 2, 0), translated to (10, 2, 0).
  EXPECT_NEAR(m.vertices[1][0], 10.0, 1e-12);
  EXPECT_NEAR(m.vertices[1][1], 2.0, 1e-12);
  EXPECT_NEAR(m.vertices[1][2], 0.0, 1e-12);
  EXPECT_EQ(m.triangles[0], (std::array<std::uint32_t, 3>{0, 2, 1}));
}

TEST(SceneJsonMesh, QuadsAreTriangulatedAndScaledPerAxis) {
  json j = mesh_scene("quad_cube.obj");
  j["occluders"][0]["scale"] = {1, 2, 3};
  const Scene s = parse_scene(j, data_opts());
  const auto& m = std::get<MeshOccluder>(s.occluders[0].shape);
  EXPECT_EQ(m.triangles.size(), 12u);
  EXPECT_EQ(m.vertices[6], (Vec3{0.5, 1.0, 1.5}));
  for (const auto& t : m.triangles) {
    for (auto i : t) EXPECT_LT(i, m.vertices.size());
  }
}

TEST(SceneJsonMesh, ExampleTorusLoads) {
  SceneLoadOptions o;
  o.assets_dir = kSourceDir / "examples";
  const Scene s = parse_scene(mesh_scene("meshes/torus.obj"), o);
  const auto& m = std::get<MeshOccluder>(s.occluders[0].shape);
  EXPECT_GE(m.triangles.size(), 100u);
  EXPECT_LE(m.triangles.size(), 500u);
}

TEST(SceneJsonMesh, ForbiddenAbsolutePath) {
  EXPECT_REJECTED(mesh_scene((kDataDir / "tetrahedron.obj").string()), data_opts(),
                  "forbidden_path", "/occluders/0/file");
}

TEST(SceneJsonMesh, ForbiddenDotDot) {
  EXPECT_REJECTED(mesh_scene("../data/tetrahedron.obj"), data_opts(), "forbidden_path",
                  "/occluders/0/file");
  EXPECT_REJECTED(mesh_scene("sub/../tetrahedron.obj"), data_opts(), "forbidden_path",
                  "/occluders/0/file");
}

TEST(SceneJsonMesh, ForbiddenWithoutAssetsDir) {
  EXPECT_REJECTED(mesh_scene("tetrahedron.obj"), SceneLoadOptions{}, "forbidden_path",
                  "/occluders/0/file");
}

TEST(SceneJsonMesh, ForbiddenSymlinkOutOfAssets) {
  const fs::path dir =
      fs::temp_directory_path() /
      ("beamcast_assets_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::create_symlink(kDataDir / "tetrahedron.obj", dir / "link.obj");
  SceneLoadOptions o;
  o.assets_dir = dir;
  EXPECT_REJECTED(mesh_scene("link.obj"), o, "forbidden_path", "/occluders/0/file");
  fs::remove_all(dir);
}

TEST(SceneJsonMesh, FileNotFound) {
  EXPECT_REJECTED(mesh_scene("missing.obj"), data_opts(), "file_not_found", "/occluders/0/file");
  // A directory is there but is not a regular file.
  EXPECT_REJECTED(mesh_scene("."), data_opts(), "forbidden_path", "/occluders/0/file");
}

TEST(SceneJsonMesh, BadMesh) {
  EXPECT_REJECTED(mesh_scene("bad_index.obj"), data_opts(), "bad_mesh", "/occluders/0/file");
  EXPECT_REJECTED(mesh_scene("no_faces.obj"), data_opts(), "bad_mesh", "/occluders/0/file");
}

TEST(SceneJsonMesh, TriangleLimitIsSummedOverScene) {
  SceneLoadOptions o = data_opts();
  o.limits.max_mesh_triangles = 6;  // one tetrahedron (4) fits, two (8) do not
  json j = mesh_scene("tetrahedron.obj");
  EXPECT_NO_THROW(parse_scene(j, o));
  j["occluders"].push_back({{"type", "mesh"}, {"file", "tetrahedron.obj"}});
  EXPECT_REJECTED(j, o, "limit_exceeded", "/occluders/1/file");
}

TEST(SceneJsonMesh, ZeroScaleRejected) {
  json j = mesh_scene("tetrahedron.obj");
  j["occluders"][0]["scale"] = {1, 0, 1};
  EXPECT_REJECTED(j, data_opts(), "out_of_range", "/occluders/0/scale");
}

// ---- Rejections, one per class ------------------------------------------------------

TEST(SceneJsonReject, NotFinite) {
  // A json document built in code (not parsed from text) can hold inf and NaN.
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_REJECTED(with(base(), "/cameras/0/fov_y", inf), SceneLoadOptions{}, "not_finite",
                  "/cameras/0/fov_y");
  EXPECT_REJECTED(with(base(), "/beams/0/center/1", -inf), SceneLoadOptions{}, "not_finite",
                  "/beams/0/center/1");
  EXPECT_REJECTED(with(base(), "/light", {{"intensity", std::nan("")}}), SceneLoadOptions{},
                  "not_finite", "/light/intensity");
}

TEST(SceneJsonReject, OutOfRangeCoordinate) {
  EXPECT_REJECTED(with(base(), "/cameras/0/position/2", 1e13), SceneLoadOptions{}, "out_of_range",
                  "/cameras/0/position/2");
}

TEST(SceneJsonReject, AbsurdSizes) {
  EXPECT_REJECTED(with(base(), "/occluders/0/size/0", 1e13), SceneLoadOptions{}, "out_of_range",
                  "/occluders/0/size/0");
  EXPECT_REJECTED(with(base(), "/beams/0/radius", 1e300), SceneLoadOptions{}, "out_of_range",
                  "/beams/0/radius");
  EXPECT_REJECTED(with(base(), "/occluders/0/size/2", 0), SceneLoadOptions{}, "out_of_range",
                  "/occluders/0/size/2");
}

TEST(SceneJsonReject, ZeroAndNegativeRadius) {
  for (double r : {0.0, -1.0}) {
    const ErrorInfo e = error_of(with(base(), "/beams/1/radius", r));
    EXPECT_EQ(e.code, "out_of_range");
    EXPECT_EQ(e.path, "/beams/1/radius");
  }
  const ErrorInfo e = error_of(with(base(), "/beams/0/radius", -1));
  EXPECT_NE(e.message.find("got -1"), std::string::npos) << e.message;
}

TEST(SceneJsonReject, WrongType) {
  const ErrorInfo e = error_of(with(base(), "/beams/0/radius", "1"));
  EXPECT_EQ(e.code, "wrong_type");
  EXPECT_EQ(e.path, "/beams/0/radius");
  EXPECT_NE(e.message.find("number"), std::string::npos) << e.message;
  EXPECT_REJECTED(with(base(), "/beams/0/center", json::array({1, 2})), SceneLoadOptions{},
                  "wrong_type", "/beams/0/center");
  EXPECT_REJECTED(with(base(), "/beams/1/caps", json::array({1, 0})), SceneLoadOptions{},
                  "wrong_type", "/beams/1/caps/0");
  EXPECT_REJECTED(json::array(), SceneLoadOptions{}, "wrong_type", "");
  EXPECT_REJECTED(with(base(), "/beams", json::object()), SceneLoadOptions{}, "wrong_type",
                  "/beams");
  EXPECT_REJECTED(with(base(), "/cameras/0/width", 100.5), SceneLoadOptions{}, "wrong_type",
                  "/cameras/0/width");
  EXPECT_REJECTED(with(base(), "/cameras/0/position/0", true), SceneLoadOptions{}, "wrong_type",
                  "/cameras/0/position/0");
}

TEST(SceneJsonReject, MissingField) {
  EXPECT_REJECTED(without(base(), "/beams/0", "radius"), SceneLoadOptions{}, "missing_field",
                  "/beams/0/radius");
  EXPECT_REJECTED(without(base(), "/beams/1", "p1"), SceneLoadOptions{}, "missing_field",
                  "/beams/1/p1");
  EXPECT_REJECTED(without(base(), "", "cameras"), SceneLoadOptions{}, "missing_field", "/cameras");
  EXPECT_REJECTED(without(base(), "/occluders/0", "type"), SceneLoadOptions{}, "missing_field",
                  "/occluders/0/type");
}

TEST(SceneJsonReject, UnknownField) {
  json j = base();
  j["beams"][0]["raduis"] = 1;
  EXPECT_REJECTED(j, SceneLoadOptions{}, "unknown_field", "/beams/0/raduis");
  EXPECT_REJECTED(with(base(), "/beam", json::array()), SceneLoadOptions{}, "unknown_field",
                  "/beam");
  // Capsule-only fields are unknown on a sphere.
  EXPECT_REJECTED(with(base(), "/beams/0/caps", json::array({true, true})), SceneLoadOptions{},
                  "unknown_field", "/beams/0/caps");
  // Pointer escaping of odd keys.
  EXPECT_REJECTED(with(base(), "/cameras/0/a~1b", 1), SceneLoadOptions{}, "unknown_field",
                  "/cameras/0/a~1b");
}

TEST(SceneJsonReject, InvalidValue) {
  const ErrorInfo e = error_of(with(base(), "/output", {{"tone", "linear"}}));
  EXPECT_EQ(e.code, "invalid_value");
  EXPECT_EQ(e.path, "/output/tone");
  EXPECT_NE(e.message.find("\"reinhard\""), std::string::npos) << e.message;
  EXPECT_REJECTED(with(base(), "/beams/0/density", "cubic"), SceneLoadOptions{}, "invalid_value",
                  "/beams/0/density");
  EXPECT_REJECTED(with(base(), "/beams/0/type", "cone"), SceneLoadOptions{}, "invalid_value",
                  "/beams/0/type");
  EXPECT_REJECTED(with(base(), "/cameras/0/projection", "fisheye"), SceneLoadOptions{},
                  "invalid_value", "/cameras/0/projection");
  EXPECT_REJECTED(with(base(), "/output", {{"bit_depth", 12}}), SceneLoadOptions{}, "invalid_value",
                  "/output/bit_depth");
  EXPECT_REJECTED(with(base(), "/version", 2), SceneLoadOptions{}, "invalid_value", "/version");
  EXPECT_REJECTED(with(base(), "/cameras/0/name", "has space"), SceneLoadOptions{}, "invalid_value",
                  "/cameras/0/name");
  EXPECT_REJECTED(with(base(), "/cameras", json::array()), SceneLoadOptions{}, "invalid_value",
                  "/cameras");
  EXPECT_REJECTED(with(base(), "/occluders/0/rotation", json::array({0, 0, 0, 0})),
                  SceneLoadOptions{}, "invalid_value", "/occluders/0/rotation");
  EXPECT_REJECTED(with(base(), "/light", {{"direction", {0, 0, 0}}}), SceneLoadOptions{},
                  "invalid_value", "/light/direction");
}

TEST(SceneJsonReject, OtherRanges) {
  EXPECT_REJECTED(with(base(), "/cameras/0/fov_y", 0), SceneLoadOptions{}, "out_of_range",
                  "/cameras/0/fov_y");
  EXPECT_REJECTED(with(base(), "/cameras/0/far", 0.001), SceneLoadOptions{}, "out_of_range",
                  "/cameras/0/far");
  EXPECT_REJECTED(with(with(base(), "/cameras/0/near", 1e-9), "/cameras/0/far", 1e7),
                  SceneLoadOptions{}, "out_of_range", "/cameras/0/far");
  EXPECT_REJECTED(with(base(), "/occluders/0/albedo", {0.5, 1.5, 0.5}), SceneLoadOptions{},
                  "out_of_range", "/occluders/0/albedo/1");
  EXPECT_REJECTED(with(base(), "/light", {{"ambient", 2}}), SceneLoadOptions{}, "out_of_range",
                  "/light/ambient");
  EXPECT_REJECTED(with(base(), "/output", {{"exposure", 0}}), SceneLoadOptions{}, "out_of_range",
                  "/output/exposure");
  EXPECT_REJECTED(with(base(), "/beams/0/color", {1, -0.1, 1}), SceneLoadOptions{}, "out_of_range",
                  "/beams/0/color/1");
  EXPECT_REJECTED(with(base(), "/beams/0/density", {{"type", "gaussian"}, {"sigma", 11}}),
                  SceneLoadOptions{}, "out_of_range", "/beams/0/density/sigma");
  EXPECT_REJECTED(with(base(), "/render", {{"f_table", 8}}), SceneLoadOptions{}, "out_of_range",
                  "/render/f_table");
  EXPECT_REJECTED(with(base(), "/cameras/0/width", 0), SceneLoadOptions{}, "out_of_range",
                  "/cameras/0/width");
}

TEST(SceneJsonReject, DensityTable) {
  EXPECT_REJECTED(with(base(), "/beams/0/density", {{"type", "table"}, {"samples", {0, 0, 0}}}),
                  SceneLoadOptions{}, "invalid_value", "/beams/0/density/samples");
  EXPECT_REJECTED(with(base(), "/beams/0/density", {{"type", "table"}, {"samples", {1}}}),
                  SceneLoadOptions{}, "invalid_value", "/beams/0/density/samples");
  EXPECT_REJECTED(with(base(), "/beams/0/density", {{"type", "table"}, {"samples", {1, -1}}}),
                  SceneLoadOptions{}, "out_of_range", "/beams/0/density/samples/1");
  EXPECT_REJECTED(with(base(), "/beams/0/density", {{"type", "table"}}), SceneLoadOptions{},
                  "missing_field", "/beams/0/density/samples");
}

// limit_exceeded, one per named limit.
TEST(SceneJsonReject, LimitExceeded) {
  SceneLoadOptions o;
  o.limits.max_beams = 1;
  EXPECT_REJECTED(base(), o, "limit_exceeded", "/beams");
  o = {};
  o.limits.max_occluders = 0;
  EXPECT_REJECTED(base(), o, "limit_exceeded", "/occluders");
  o = {};
  o.limits.max_cameras = 1;
  json two = base();
  two["cameras"].push_back(json::object());
  EXPECT_REJECTED(two, o, "limit_exceeded", "/cameras");

  const ErrorInfo e = error_of(with(base(), "/cameras/0/width", 8193));
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_EQ(e.path, "/cameras/0/width");
  EXPECT_NE(e.message.find("max_width"), std::string::npos) << e.message;
  EXPECT_NE(e.message.find("8193"), std::string::npos) << e.message;

  EXPECT_REJECTED(with(base(), "/cameras/0/height", 100000), SceneLoadOptions{}, "limit_exceeded",
                  "/cameras/0/height");
  o = {};
  o.limits.max_pixels = 1000;
  EXPECT_REJECTED(with(with(base(), "/cameras/0/width", 100), "/cameras/0/height", 11), o,
                  "limit_exceeded", "/cameras/0/width");
  o = {};
  o.limits.max_density_samples = 3;
  EXPECT_REJECTED(with(base(), "/beams/0/density", {{"type", "table"}, {"samples", {1, 1, 1, 0}}}),
                  o, "limit_exceeded", "/beams/0/density/samples");
  EXPECT_REJECTED(with(base(), "/render", {{"table_size", {64, 2048}}}), SceneLoadOptions{},
                  "limit_exceeded", "/render/table_size/1");
  EXPECT_REJECTED(with(base(), "/render", {{"table_size", 4}}), SceneLoadOptions{}, "out_of_range",
                  "/render/table_size");
}

TEST(SceneJsonReject, DegenerateCapsule) {
  const ErrorInfo e = error_of(with(base(), "/beams/1/p1", {0, 0, 0}));
  EXPECT_EQ(e.code, "degenerate_capsule");
  EXPECT_EQ(e.path, "/beams/1/p1");
  EXPECT_NE(e.message.find("sphere"), std::string::npos) << e.message;
  // Tolerance scales with the radius: 1e-9 * 1000 = 1e-6.
  json j = with(base(), "/beams/1/p1", {5e-7, 0, 0});
  j["beams"][1]["radius"] = 1000;
  EXPECT_REJECTED(j, SceneLoadOptions{}, "degenerate_capsule", "/beams/1/p1");
}

TEST(SceneJsonReject, DuplicateCameraName) {
  json j = base();
  j["cameras"].push_back({{"name", "side"}});
  j["cameras"].push_back({{"name", "main"}});
  EXPECT_REJECTED(j, SceneLoadOptions{}, "duplicate_name", "/cameras/2/name");
}

TEST(SceneJsonReject, ConflictingFields) {
  EXPECT_REJECTED(with(base(), "/cameras/0/rotation", {1, 0, 0, 0}), SceneLoadOptions{},
                  "conflicting_fields", "/cameras/0/rotation");
  json j = without(base(), "/cameras/0", "target");
  j["cameras"][0]["rotation"] = {1, 0, 0, 0};
  j["cameras"][0]["up"] = {0, 1, 0};
  EXPECT_REJECTED(j, SceneLoadOptions{}, "conflicting_fields", "/cameras/0/up");
}

// Camera vectors that would make camera_basis produce NaN.
TEST(SceneJsonReject, DegenerateCameraVectors) {
  EXPECT_REJECTED(with(base(), "/cameras/0/up", {0, 0, 2}), SceneLoadOptions{}, "invalid_value",
                  "/cameras/0/up");
  EXPECT_REJECTED(with(base(), "/cameras/0/target", {0, 0, 5}), SceneLoadOptions{}, "invalid_value",
                  "/cameras/0/target");
  EXPECT_REJECTED(with(base(), "/cameras/0/up", {0, 0, 0}), SceneLoadOptions{}, "invalid_value",
                  "/cameras/0/up");
  // Subnormal components (whose normalization overflowed) are refused as
  // numbers (issue 43); tiny normal ones are directions like any other.
  EXPECT_REJECTED(with(base(), "/cameras/0/up", {0, 1e-320, 0}), SceneLoadOptions{},
                  "out_of_range", "/cameras/0/up/1");
  EXPECT_REJECTED(with(base(), "/light", {{"direction", {0, -1e-320, 0}}}), SceneLoadOptions{},
                  "out_of_range", "/light/direction/1");
  EXPECT_NO_THROW(parse_scene(with(base(), "/cameras/0/up", {0, 1e-300, 0}), SceneLoadOptions{}));
  EXPECT_NO_THROW(parse_scene(with(base(), "/light", {{"direction", {0, -1e-300, 0}}}),
                              SceneLoadOptions{}));
  // Default up (+Y) with a target straight below.
  EXPECT_REJECTED(with(base(), "/cameras/0/target", {0, -10, 5}), SceneLoadOptions{},
                  "invalid_value", "/cameras/0/target");
  EXPECT_REJECTED(with(base(), "/cameras/0/rotation", {0, 0, 0, 0}) /* with target */,
                  SceneLoadOptions{}, "conflicting_fields", "/cameras/0/rotation");
}

// ---- Files ------------------------------------------------------------------------

fs::path write_temp(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / name;
  std::ofstream(p) << text;
  return p;
}

TEST(SceneFile, FileNotFound) {
  try {
    load_scene_file(kDataDir / "no_such_scene.json", {});
    FAIL() << "accepted";
  } catch (const ProtocolError& e) {
    EXPECT_EQ(e.info().code, "file_not_found");
    EXPECT_EQ(e.info().path, "");
  }
}

TEST(SceneFile, BadJsonReportsBytePosition) {
  const fs::path p = write_temp("beamcast_bad.json", R"({"cameras": [{}],})");
  try {
    load_scene_file(p, {});
    FAIL() << "accepted";
  } catch (const ProtocolError& e) {
    EXPECT_EQ(e.info().code, "bad_json");
    EXPECT_EQ(e.info().path, "");
    EXPECT_NE(e.info().message.find("byte 18"), std::string::npos) << e.info().message;
  }
  fs::remove(p);
}

// nlohmann 3.11 refuses 1e999 while parsing text (it does not produce inf);
// load_scene_file reports that as not_finite rather than as a syntax error.
TEST(SceneFile, OverflowingNumberIsNotFinite) {
  const fs::path p = write_temp("beamcast_inf.json", R"({"cameras": [{"fov_y": 1e999}]})");
  try {
    load_scene_file(p, {});
    FAIL() << "accepted";
  } catch (const ProtocolError& e) {
    EXPECT_EQ(e.info().code, "not_finite");
    EXPECT_NE(e.info().message.find("1e999"), std::string::npos) << e.info().message;
  }
  fs::remove(p);
}

TEST(SceneFile, LoadsValidFile) {
  const fs::path p = write_temp("beamcast_ok.json", base().dump(2));
  const Scene s = load_scene_file(p, {});
  EXPECT_EQ(s.beams.size(), 2u);
  fs::remove(p);
}

// Every ```json block in docs/scene-format.md is a complete scene and must parse,
// with meshes resolved against examples/.
TEST(SceneDocs, ExamplesParse) {
  std::ifstream in(kSourceDir / "docs" / "scene-format.md");
  ASSERT_TRUE(in) << "docs/scene-format.md missing";
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string doc = ss.str();
  const std::regex block("```json\\n([\\s\\S]*?)```");
  SceneLoadOptions o;
  o.assets_dir = kSourceDir / "examples";
  int count = 0;
  for (auto it = std::sregex_iterator(doc.begin(), doc.end(), block); it != std::sregex_iterator();
       ++it) {
    ++count;
    const std::string text = (*it)[1].str();
    try {
      parse_scene(json::parse(text), o);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "example " << count << " failed: " << e.what() << "\n" << text;
    }
  }
  EXPECT_GE(count, 4);
}

}  // namespace
}  // namespace beamcast
