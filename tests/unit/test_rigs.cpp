// Camera rigs (orbit, cube map, stereo), their JSON validation, command-line
// rig specs and camera paths: geometry checked against the definitions in
// docs/scene-format.md, errors against their JSON paths.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "protocol/camera.hpp"
#include "protocol/camera_path.hpp"
#include "protocol/rigs.hpp"
#include "protocol/scene_json.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

// Double math on values of order 1-10: 1e-12 is far below any real error and
// far above rounding (~1e-15).
constexpr double kTol = 1e-12;

Scene scene_with(const json& cameras) {
  return parse_scene({{"beams", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1}}}},
                      {"cameras", cameras}},
                     SceneLoadOptions{});
}

ErrorInfo error_of(const json& cameras) {
  try {
    scene_with(cameras);
  } catch (const ProtocolError& e) {
    return e.info();
  }
  ADD_FAILURE() << "no error for " << cameras.dump();
  return {};
}

TEST(Rigs, OrbitCircleIsEvenlySpacedAtRadiusAndElevationLookingAtTarget) {
  for (int count : {1, 3, 36}) {
    for (double elevation : {-45.0, 0.0, 30.0}) {
      const Vec3 target{1, 2, 3};
      const Scene s = scene_with({{{"rig", "orbit"}, {"count", count}, {"target", target},
                                   {"radius", 4}, {"elevation", elevation}, {"start", 10}}});
      ASSERT_EQ(s.cameras.size(), static_cast<std::size_t>(count));
      for (int i = 0; i < count; ++i) {
        const Camera& c = s.cameras[i];
        const Vec3 off = c.position - target;
        EXPECT_NEAR(length(off), 4.0, kTol);
        EXPECT_NEAR(off[1], 4.0 * std::sin(elevation * M_PI / 180), kTol);  // axis +Y
        ASSERT_TRUE(c.target);
        EXPECT_NEAR(length(*c.target - target), 0.0, kTol);
        // Azimuth from +Z towards +X (right-handed about +Y), start + 360 i / count.
        const double az = std::atan2(off[0], off[2]) * 180 / M_PI;
        const double want = std::remainder(10.0 + 360.0 * i / count, 360.0);
        EXPECT_NEAR(std::remainder(az - want, 360.0), 0.0, 1e-9) << i;
        char name[32];
        std::snprintf(name, sizeof name, "orbit_%03d", i);
        EXPECT_EQ(c.name, name);
      }
    }
  }
}

TEST(Rigs, OrbitSphereCoversBothHemispheresEvenly) {
  const Scene s = scene_with(
      {{{"rig", "orbit"}, {"layout", "sphere"}, {"count", 200}, {"radius", 2}, {"name", "s"}}});
  ASSERT_EQ(s.cameras.size(), 200u);
  // Equal-area bands: the mean of the axis coordinate is 0 and its spread that
  // of a uniform distribution on [-r, r] (variance r^2 / 3), within the
  // discretization 1/count.
  double sum = 0, sum2 = 0;
  for (const Camera& c : s.cameras) {
    EXPECT_NEAR(length(c.position), 2.0, kTol);
    sum += c.position[1];
    sum2 += c.position[1] * c.position[1];
  }
  EXPECT_NEAR(sum / 200, 0.0, 1e-9);
  EXPECT_NEAR(sum2 / 200, 4.0 / 3.0, 4.0 / 200);
  EXPECT_EQ(s.cameras[199].name, "s_199");
}

TEST(Rigs, CubemapFacesAreSquareNinetyDegreesInDocumentedOrder) {
  const Scene s = scene_with({{{"rig", "cubemap"}, {"position", {1, 1, 1}}, {"size", 64},
                               {"name", "env"}, {"far", 50}}});
  ASSERT_EQ(s.cameras.size(), 6u);
  const char* names[6] = {"env_px", "env_nx", "env_py", "env_ny", "env_pz", "env_nz"};
  std::set<std::array<double, 3>> forwards;
  for (int i = 0; i < 6; ++i) {
    const Camera& c = s.cameras[i];
    EXPECT_EQ(c.name, names[i]);
    EXPECT_EQ(c.width, 64);
    EXPECT_EQ(c.height, 64);
    EXPECT_EQ(c.fov_y_deg, 90.0);
    EXPECT_EQ(c.far_plane, 50.0);
    const CameraBasis b = camera_basis(c);
    EXPECT_NEAR(length(b.forward - kCubemapFaces[i].forward), 0.0, kTol);
    EXPECT_NEAR(length(b.up - kCubemapFaces[i].up), 0.0, kTol);
    forwards.insert(b.forward);
  }
  EXPECT_EQ(forwards.size(), 6u);
  // Adjacent faces share edges: 90 degrees each way covers the full sphere
  // only if the fov is exactly 90 (checked above) and the faces are the six
  // axis directions (checked above).
}

TEST(Rigs, StereoEyesAreSeparatedAlongRightAndConverge) {
  const Scene s = scene_with({{{"rig", "stereo"}, {"position", {0, 0, 10}},
                               {"target", {0, 0, 0}}, {"eye_separation", 0.5},
                               {"convergence", 4}}});
  ASSERT_EQ(s.cameras.size(), 2u);
  const Camera& l = s.cameras[0];
  const Camera& r = s.cameras[1];
  EXPECT_EQ(l.name, "stereo_left");
  EXPECT_EQ(r.name, "stereo_right");
  EXPECT_NEAR(length(l.position - Vec3{-0.25, 0, 10}), 0.0, kTol);
  EXPECT_NEAR(length(r.position - Vec3{0.25, 0, 10}), 0.0, kTol);
  EXPECT_NEAR(length(*l.target - Vec3{0, 0, 6}), 0.0, kTol);
  EXPECT_NEAR(length(*r.target - Vec3{0, 0, 6}), 0.0, kTol);
  // Default convergence: the target distance.
  const Scene d = scene_with({{{"rig", "stereo"}, {"position", {0, 0, 10}}, {"target", {0, 0, 0}}}});
  EXPECT_NEAR(length(*d.cameras[0].target), 0.0, kTol);
}

TEST(Rigs, RigsMixWithCamerasAndCountTowardsTheLimit) {
  const Scene s = scene_with({{{"name", "main"}}, {{"rig", "stereo"}, {"target", {0, 0, 0}}}});
  ASSERT_EQ(s.cameras.size(), 3u);
  EXPECT_EQ(s.cameras[0].name, "main");
  const ErrorInfo e = error_of({{{"rig", "orbit"}, {"count", 200}}, {{"rig", "orbit"}, {"count", 57},
                                                                     {"name", "b"}}});
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_EQ(e.path, "/cameras/1");
}

TEST(Rigs, ErrorsCarryJsonPaths) {
  struct Case {
    json cameras;
    const char* code;
    const char* path;
  };
  const Case cases[] = {
      {{{{"rig", "ring"}}}, "invalid_value", "/cameras/0/rig"},
      {{{{"rig", "orbit"}}}, "missing_field", "/cameras/0/count"},
      {{{{"rig", "orbit"}, {"count", 0}}}, "out_of_range", "/cameras/0/count"},
      {{{{"rig", "orbit"}, {"count", 4}, {"radius", -1}}}, "out_of_range", "/cameras/0/radius"},
      {{{{"rig", "orbit"}, {"count", 4}, {"elevation", 90}}}, "out_of_range",
       "/cameras/0/elevation"},
      {{{{"rig", "orbit"}, {"count", 4}, {"axis", {0, 0, 0}}}}, "invalid_value",
       "/cameras/0/axis"},
      {{{{"rig", "orbit"}, {"count", 4}, {"layout", "sphere"}, {"elevation", 3}}},
       "conflicting_fields", "/cameras/0/elevation"},
      {{{{"rig", "orbit"}, {"count", 4}, {"fov_y", 200}}}, "out_of_range", "/cameras/0/fov_y"},
      {{{{"rig", "orbit"}, {"count", 4}, {"spin", 1}}}, "unknown_field", "/cameras/0/spin"},
      {{{{"rig", "cubemap"}, {"fov_y", 60}}}, "unknown_field", "/cameras/0/fov_y"},
      {{{{"rig", "cubemap"}, {"size", 0}}}, "out_of_range", "/cameras/0/size"},
      {{{{"rig", "stereo"}}}, "missing_field", "/cameras/0/target"},
      {{{{"rig", "stereo"}, {"target", {0, 0, 5}}}}, "invalid_value", "/cameras/0/target"},
      {{{{"rig", "stereo"}, {"target", {0, 0, 0}}, {"eye_separation", -1}}}, "out_of_range",
       "/cameras/0/eye_separation"},
      {{{{"rig", "stereo"}, {"target", {0, 0, 0}}, {"up", {0, 0, 1}}}}, "invalid_value",
       "/cameras/0/up"},
      {{{{"rig", "stereo"}, {"target", {0, 0, 0}}},
        {{"rig", "stereo"}, {"target", {0, 0, 0}}}},
       "duplicate_name", "/cameras/1/name"},
  };
  for (const Case& c : cases) {
    const ErrorInfo e = error_of(c.cameras);
    EXPECT_EQ(e.code, c.code) << c.cameras.dump() << ": " << e.message;
    EXPECT_EQ(e.path, c.path) << c.cameras.dump() << ": " << e.message;
  }
}

TEST(Rigs, CameraJsonRoundTrips) {
  const Scene s = scene_with({{{"rig", "orbit"}, {"count", 3}, {"elevation", 12.5},
                               {"width", 33}, {"near", 0.5}},
                              {{"name", "q"}, {"rotation", {0.5, 0.5, 0.5, 0.5}},
                               {"projection", "orthographic"}}});
  for (const Camera& c : s.cameras) {
    const Camera back = parse_camera(camera_to_json(c), "", SceneLimits{});
    EXPECT_EQ(back.name, c.name);
    EXPECT_EQ(back.position, c.position);
    EXPECT_EQ(back.target, c.target);
    EXPECT_EQ(back.rotation, c.rotation);
    EXPECT_EQ(back.projection, c.projection);
    EXPECT_EQ(back.width, c.width);
    EXPECT_EQ(back.near_plane, c.near_plane);
  }
}

TEST(RigSpec, OrbitStartsAtTheFirstCameraAroundTheBeams) {
  Scene s = parse_scene({{"beams",
                          {{{"type", "sphere"}, {"center", {2, 0, 0}}, {"radius", 1}},
                           {{"type", "sphere"}, {"center", {4, 2, 0}}, {"radius", 1}}}},
                         {"cameras", {{{"position", {3, 4, 8}}, {"target", {0, 0, 0}},
                                       {"width", 40}, {"height", 30}}}}},
                        SceneLoadOptions{});
  const auto cams = rig_from_spec("orbit:12", s);
  ASSERT_EQ(cams.size(), 12u);
  const Vec3 centre{3, 1, 0};
  EXPECT_NEAR(length(cams[0].position - s.cameras[0].position), 0.0, 1e-9);
  for (const Camera& c : cams) {
    EXPECT_NEAR(length(c.position - centre), length(s.cameras[0].position - centre), 1e-9);
    EXPECT_NEAR(length(*c.target - centre), 0.0, kTol);
    EXPECT_EQ(c.width, 40);
    EXPECT_EQ(c.height, 30);
  }
  EXPECT_EQ(rig_from_spec("cubemap", s).size(), 6u);
  EXPECT_EQ(rig_from_spec("cubemap:16", s)[0].height, 16);
  const auto st = rig_from_spec("stereo:0.2", s);
  ASSERT_EQ(st.size(), 2u);
  EXPECT_NEAR(length(st[0].position - st[1].position), 0.2, kTol);
  for (const char* bad : {"orbit:0", "orbit:2.5", "orbit:x", "ring", "cubemap:-3", "stereo:"}) {
    EXPECT_THROW(rig_from_spec(bad, s), ProtocolError) << bad;
  }
}

TEST(CameraPathTest, PassesThroughKeyframesAndInterpolates) {
  const json file = {{"interpolation", "catmull_rom"},
                     {"camera", {{"width", 20}, {"height", 10}}},
                     {"keyframes",
                      {{{"time", 0}, {"position", {0, 0, 10}}, {"target", {0, 0, 0}}},
                       {{"time", 1}, {"position", {10, 0, 0}}, {"target", {0, 1, 0}}},
                       {{"time", 3}, {"position", {0, 0, -10}}, {"target", {0, 0, 0}}}}}};
  Camera base;
  base.fov_y_deg = 30;
  const CameraPath cr = parse_camera_path(file, base, SceneLimits{});
  EXPECT_EQ(cr.base.width, 20);
  EXPECT_EQ(cr.base.fov_y_deg, 30);
  for (const auto& k : cr.keyframes) {
    const CameraKeyframe s = sample_camera_path(cr, k.time);
    EXPECT_NEAR(length(s.position - k.position), 0.0, kTol);
    EXPECT_NEAR(length(s.target - k.target), 0.0, kTol);
  }
  // Catmull-Rom bulges past the chord; linear stays on it.
  json lin = file;
  lin["interpolation"] = "linear";
  const CameraPath lp = parse_camera_path(lin, base, SceneLimits{});
  const CameraKeyframe a = sample_camera_path(lp, 0.5);
  EXPECT_NEAR(length(a.position - Vec3{5, 0, 5}), 0.0, kTol);
  EXPECT_NEAR(length(a.target - Vec3{0, 0.5, 0}), 0.0, kTol);
  const CameraKeyframe b = sample_camera_path(cr, 0.5);
  EXPECT_GT(length(b.position), length(a.position) + 0.1);
  // N frames from the first to the last time, numbered.
  const auto cams = expand_camera_path(cr, 7);
  ASSERT_EQ(cams.size(), 7u);
  EXPECT_EQ(cams[0].name, "frame_0000");
  EXPECT_EQ(cams[6].name, "frame_0006");
  EXPECT_NEAR(length(cams[6].position - Vec3{0, 0, -10}), 0.0, kTol);
  EXPECT_NEAR(length(cams[3].position - sample_camera_path(cr, 1.5).position), 0.0, kTol);
  EXPECT_EQ(expand_camera_path(cr).size(), 3u);  // one per keyframe by default
}

TEST(CameraPathTest, ErrorsCarryPaths) {
  const json key0 = {{"position", {0, 0, 5}}, {"target", {0, 0, 0}}};
  struct Case {
    json file;
    const char* path;
  };
  const Case cases[] = {
      {{{"keyframes", json::array({key0})}}, "/keyframes"},
      {{{"keyframes", {key0, {{"position", {0, 0, 5}}}}}}, "/keyframes/1/target"},
      {{{"keyframes", {key0, {{"position", {1, 0, 0}}, {"target", {1, 0, 0}}}}}},
       "/keyframes/1/target"},
      {{{"keyframes", {{{"time", 2}, {"position", {0, 0, 5}}, {"target", {0, 0, 0}}},
                       {{"time", 1}, {"position", {0, 1, 5}}, {"target", {0, 0, 0}}}}}},
       "/keyframes/1/time"},
      {{{"keyframes", {key0, key0}}, {"interpolation", "cubic"}}, "/interpolation"},
      {{{"keyframes", {key0, key0}}, {"frames", 0}}, "/frames"},
      {{{"keyframes", {key0, key0}}, {"camera", {{"width", 0}}}}, "/camera/width"},
      {{{"keyframes", {key0, key0}}, {"camera", {{"position", {0, 0, 1}}}}}, "/camera/position"},
  };
  for (const Case& c : cases) {
    try {
      parse_camera_path(c.file, Camera{}, SceneLimits{});
      ADD_FAILURE() << "no error for " << c.file.dump();
    } catch (const ProtocolError& e) {
      EXPECT_EQ(e.info().path, c.path) << c.file.dump() << ": " << e.info().message;
    }
  }
  // Interpolation through a degenerate pose: the target crosses the position.
  const json cross = {{"interpolation", "linear"},
                      {"keyframes",
                       {{{"position", {0, 0, 0}}, {"target", {1, 0, 0}}},
                        {{"position", {1, 0, 0}}, {"target", {0, 0, 0}}}}}};
  const CameraPath p = parse_camera_path(cross, Camera{}, SceneLimits{});
  EXPECT_THROW(expand_camera_path(p, 3), ProtocolError);
}

}  // namespace
}  // namespace beamcast
