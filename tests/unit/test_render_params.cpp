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

}  // namespace
}  // namespace beamcast
