// `render` params of interactive quality (protocol/request.hpp): defaults,
// accepted values, and errors with their JSON paths.
#include <gtest/gtest.h>

#include "protocol/request.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

ErrorInfo error_of(const json& params) {
  try {
    parse_render_params(params, SceneLimits{});
  } catch (const ProtocolError& e) {
    return e.info();
  }
  ADD_FAILURE() << "no error for " << params.dump();
  return {};
}

TEST(RenderParams, QualityDefaultsToFullWithoutController) {
  EXPECT_FALSE(parse_render_params({{"scene_id", "demo"}}, SceneLimits{}).quality);
  EXPECT_FALSE(parse_render_params({{"scene_id", "demo"}, {"quality", "full"}}, SceneLimits{}).quality);
}

TEST(RenderParams, AutoQualityDefaultsAndOverrides) {
  auto q = parse_render_params({{"scene_id", "demo"}, {"quality", "auto"}}, SceneLimits{}).quality;
  ASSERT_TRUE(q);
  EXPECT_EQ(q->budget_ms, 33.0);
  EXPECT_EQ(q->still_ms, 300.0);
  EXPECT_EQ(q->motion, "infer");
  EXPECT_TRUE(q->jpeg);
  q = parse_render_params({{"scene_id", "demo"},
                           {"quality", "auto"},
                           {"budget_ms", 50},
                           {"still_ms", 0},
                           {"motion", "moving"},
                           {"interactive_format", "png"}},
                          SceneLimits{})
          .quality;
  ASSERT_TRUE(q);
  EXPECT_EQ(q->budget_ms, 50.0);
  EXPECT_EQ(q->still_ms, 0.0);
  EXPECT_EQ(q->motion, "moving");
  EXPECT_FALSE(q->jpeg);
}

TEST(RenderParams, BadQualityParamsNameTheirPath) {
  const json base = {{"scene_id", "demo"}, {"quality", "auto"}};
  auto with = [&](const char* key, json v) {
    json p = base;
    p[key] = std::move(v);
    return p;
  };
  EXPECT_EQ(error_of(with("quality", "fast")).path, "/params/quality");
  EXPECT_EQ(error_of(with("quality", 1)).code, "invalid_value");
  EXPECT_EQ(error_of(with("budget_ms", 0)).code, "out_of_range");
  EXPECT_EQ(error_of(with("budget_ms", "33")).code, "wrong_type");
  EXPECT_EQ(error_of(with("still_ms", -1)).path, "/params/still_ms");
  EXPECT_EQ(error_of(with("motion", "fast")).path, "/params/motion");
  EXPECT_EQ(error_of(with("interactive_format", "webp")).path, "/params/interactive_format");
  // Controller parameters without the controller are a mistake, not ignored.
  const ErrorInfo e = error_of({{"scene_id", "demo"}, {"budget_ms", 33}});
  EXPECT_EQ(e.code, "invalid_value");
  EXPECT_EQ(e.path, "/params/budget_ms");
}

// The other render params: code and pointer of each bad value (read with the
// scene parser's ObjectReader).
TEST(RenderParams, BadParamsNameTheirPath) {
  const struct {
    json params;
    const char* code;
    const char* path;
  } cases[] = {
      {{{"scene", 5}}, "wrong_type", "/params/scene"},
      {{{"scene_id", 5}}, "wrong_type", "/params/scene_id"},
      {{{"scene_id", "a b"}}, "invalid_value", "/params/scene_id"},
      {json::object(), "missing_field", "/params"},
      {{{"scene_id", "demo"}, {"scene", json::object()}}, "conflicting_fields", "/params"},
      {{{"scene_id", "demo"}, {"cameras", json::array()}}, "invalid_value", "/params/cameras"},
      {{{"scene_id", "demo"}, {"cameras", json::object()}}, "wrong_type", "/params/cameras"},
      {{{"scene_id", "demo"}, {"output", "bright"}}, "wrong_type", "/params/output"},
      {{{"scene_id", "demo"}, {"atlas", "yes"}}, "wrong_type", "/params/atlas"},
      {{{"scene_id", "demo"}, {"encoding", 1}}, "invalid_value", "/params/encoding"},
      {{{"scene_id", "demo"}, {"sceen", 1}}, "unknown_field", "/params/sceen"},
  };
  for (const auto& c : cases) {
    const ErrorInfo e = error_of(c.params);
    EXPECT_EQ(e.code, c.code) << c.params.dump() << ": " << e.message;
    EXPECT_EQ(e.path, c.path) << c.params.dump() << ": " << e.message;
  }
  EXPECT_EQ(error_of({{"scene_id", "demo"}, {"encoding", "hex"}}).message,
            "encoding must be \"binary\" or \"base64\"");
  EXPECT_TRUE(parse_render_params({{"scene_id", "demo"}, {"encoding", "base64"}}, SceneLimits{})
                  .base64);
}

}  // namespace
}  // namespace beamcast
