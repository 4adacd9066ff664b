// resolve_render (protocol/render_request.hpp): a render request's params and
// the scene they name, resolved in one pure call: inline and stored scenes,
// output merged, cameras, and each class of bad input with its code and JSON
// path within the request, limits taken from the caller's value.
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <string>

#include "protocol/render_request.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

json scene_json() {
  return json::parse(R"({
    "beams": [{"type": "sphere", "center": [0, 0, 0], "radius": 1.0}],
    "cameras": [{"name": "front", "width": 64, "height": 48}],
    "output": {"exposure": 2.0}
  })");
}

RenderLimits limits() {
  RenderLimits l;
  l.load.limits = kServerSceneLimits;
  l.max_request_cost = 120000;
  return l;
}

// A store of one entry, "demo", as the server's SceneStore would hold it.
struct Store {
  std::map<std::string, std::shared_ptr<const StoredScene>> scenes;
  int lookups = 0;
  Store() {
    auto s = std::make_shared<StoredScene>();
    s->json = scene_json();
    s->scene = parse_scene(s->json, limits().load);
    scenes["demo"] = std::move(s);
  }
  FindStoredScene find() {
    return [this](const std::string& id) -> std::shared_ptr<const StoredScene> {
      ++lookups;
      const auto it = scenes.find(id);
      return it == scenes.end() ? nullptr : it->second;
    };
  }
};

ErrorInfo error_of(const json& params, const RenderLimits& l = limits()) {
  Store store;
  try {
    resolve_render(params, l, store.find());
  } catch (const ProtocolError& e) {
    return e.info();
  }
  ADD_FAILURE() << "no error for " << params.dump();
  return {};
}

TEST(RenderRequest, InlineSceneResolves) {
  Store store;
  const ResolvedRender r =
      resolve_render({{"scene", scene_json()}, {"output", {{"tone", "reinhard"}}}}, limits(), store.find());
  EXPECT_EQ(store.lookups, 0);
  EXPECT_FALSE(r.stored);
  ASSERT_TRUE(r.scene);
  EXPECT_EQ(r.scene->beams.size(), 1u);
  ASSERT_EQ(r.cameras.size(), 1u);
  EXPECT_EQ(r.cameras[0].name, "front");
  EXPECT_EQ(r.cameras[0].width, 64);
  // params.output merged over the scene's: its exposure kept, tone replaced.
  EXPECT_EQ(r.scene->output.exposure, 2.0);
  EXPECT_EQ(r.scene->output.tone, ToneCurve::kReinhard);
  EXPECT_GT(r.cost, 0.0);
  EXPECT_EQ(r.scene_json(), scene_json());
  EXPECT_STREQ(r.scene_path(), "/params/scene");
  EXPECT_FALSE(r.video);
}

TEST(RenderRequest, StoredSceneResolvesToTheEntry) {
  Store store;
  const ResolvedRender r = resolve_render(
      {{"scene_id", "demo"}, {"cameras", {{{"name", "side"}, {"width", 32}, {"height", 32}}}}},
      limits(), store.find());
  EXPECT_EQ(store.lookups, 1);
  ASSERT_TRUE(r.stored);
  EXPECT_EQ(r.stored, store.scenes["demo"]);
  // No output override: the entry's own scene, shared, not a copy.
  EXPECT_EQ(r.scene.get(), &store.scenes["demo"]->scene);
  ASSERT_EQ(r.cameras.size(), 1u);
  EXPECT_EQ(r.cameras[0].name, "side");
  EXPECT_EQ(&r.scene_json(), &store.scenes["demo"]->json);
  EXPECT_STREQ(r.scene_path(), "/params/scene_id");
}

TEST(RenderRequest, AutoQualityWithVideoKeepsItsParams) {
  Store store;
  const ResolvedRender r = resolve_render(
      {{"scene_id", "demo"}, {"quality", "auto"}, {"video", {{"codec", "vp8"}}}}, limits(),
      store.find());
  ASSERT_TRUE(r.params.quality);
  ASSERT_TRUE(r.video);
  EXPECT_EQ(r.video->codec, "vp8");
}

TEST(RenderRequest, BadParamsGiveTheirCodeAndPath) {
  struct Case {
    json params;
    const char* code;
    const char* path;
  };
  json two_cameras = {{{"name", "a"}}, {{"name", "b"}}};
  const Case cases[] = {
      // the params themselves
      {json::object(), "missing_field", "/params"},
      {{{"scene_id", "demo"}, {"scene", scene_json()}}, "conflicting_fields", "/params"},
      {{{"scene_id", "demo"}, {"bogus", 1}}, "unknown_field", "/params/bogus"},
      {{{"scene_id", "demo"}, {"atlas", "yes"}}, "wrong_type", "/params/atlas"},
      // the inline scene, its paths under /params/scene
      {{{"scene", {{"beams", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", -1}}}}}}},
       "out_of_range", "/params/scene/beams/0/radius"},
      // a stored scene that is not there
      {{{"scene_id", "nope"}}, "unknown_scene", "/params/scene_id"},
      // params.output over the scene's
      {{{"scene_id", "demo"}, {"output", {{"tone", "sepia"}}}}, "invalid_value", "/params/output/tone"},
      // video: one camera, no atlas
      {{{"scene_id", "demo"}, {"quality", "auto"}, {"video", {{"codec", "vp8"}}}, {"cameras", two_cameras}},
       "invalid_value", "/params/video"},
  };
  for (const Case& c : cases) {
    const ErrorInfo e = error_of(c.params);
    EXPECT_EQ(e.code, c.code) << c.params.dump() << ": " << e.message;
    EXPECT_EQ(e.path, c.path) << c.params.dump() << ": " << e.message;
  }
}

TEST(RenderRequest, LimitsComeFromTheCallersValue) {
  // The same request within the server's limits, then over limits the
  // caller tightened: each limit's error at the field that set the size.
  const json params = {{"scene_id", "demo"}, {"output", {{"supersample", 4}}}};
  Store store;
  EXPECT_NO_THROW(resolve_render(params, limits(), store.find()));

  RenderLimits narrow = limits();
  narrow.load.limits.max_width = 200;  // 64 x 4 = 256 supersampled
  ErrorInfo e = error_of(params, narrow);
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_EQ(e.path, "/params/output/supersample");

  RenderLimits cheap = limits();
  cheap.max_request_cost = 1;
  e = error_of({{"scene_id", "demo"}}, cheap);
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_EQ(e.path, "/params/scene_id");
  EXPECT_NE(e.message.find("max_request_cost = 1"), std::string::npos) << e.message;
  e = error_of({{"scene", scene_json()}, {"cameras", {{{"width", 512}, {"height", 512}}}}}, cheap);
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_EQ(e.path, "/params/cameras");

  // The atlas of 16 cameras is 4 x 64 wide: within max_width 200 each, not together.
  json cams = json::array();
  for (int i = 0; i < 16; ++i) cams.push_back({{"name", "c" + std::to_string(i)}, {"width", 64}, {"height", 48}});
  e = error_of({{"scene_id", "demo"}, {"atlas", true}, {"cameras", cams}}, narrow);
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_EQ(e.path, "/params/atlas");

  // A scene over the caller's scene limits, at its path under /params/scene.
  RenderLimits few = limits();
  few.load.limits.max_beams = 0;
  e = error_of({{"scene", scene_json()}}, few);
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_EQ(e.path.rfind("/params/scene/beams", 0), 0u) << e.path;
}

}  // namespace
}  // namespace beamcast
