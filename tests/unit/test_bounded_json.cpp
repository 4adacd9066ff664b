// The bounded request parser (protocol/bounded_json.hpp) and the request and
// frame-size rules built on it (issue 19). The server-level checks over TCP
// and WebSocket are tests/python/test_hostile.py.
#include <gtest/gtest.h>

#include <string>

#include "protocol/bounded_json.hpp"
#include "protocol/request.hpp"
#include "protocol/scene_json.hpp"

namespace beamcast {
namespace {

using json = nlohmann::json;

std::string nested_objects(int levels) {
  std::string s;
  for (int i = 0; i < levels; ++i) s += "{\"a\":";
  s += "1";
  s.append(static_cast<std::size_t>(levels), '}');
  return s;
}

TEST(BoundedJson, AcceptsExactlyTheDepthLimit) {
  const JsonLimits limits{.max_depth = 5, .max_values = 100};
  BoundedParse ok = parse_json_bounded(nested_objects(5), limits);
  ASSERT_FALSE(ok.error) << ok.error->message;
  EXPECT_EQ(json_depth(ok.value), 5);
  BoundedParse deep = parse_json_bounded(nested_objects(6), limits);
  ASSERT_TRUE(deep.error);
  EXPECT_EQ(deep.error->code, "limit_exceeded");
  EXPECT_EQ(deep.error->path, "/a/a/a/a/a");  // the sixth object
  EXPECT_NE(deep.error->message.find("max_json_depth (5)"), std::string::npos);
}

TEST(BoundedJson, MillionLevelsAreRefusedWithoutRecursion) {
  // The crash input of issue 19 at 10x and 100x its depth: refused at depth 65.
  for (int levels : {600000, 6000000}) {
    std::string text(static_cast<std::size_t>(levels), '[');
    text.append(static_cast<std::size_t>(levels), ']');
    BoundedParse p = parse_json_bounded(text, JsonLimits{});
    ASSERT_TRUE(p.error);
    EXPECT_EQ(p.error->code, "limit_exceeded");
    EXPECT_EQ(std::count(p.error->path.begin(), p.error->path.end(), '/'), 64);
  }
}

TEST(BoundedJson, ValueCountLimit) {
  const JsonLimits limits{.max_depth = 64, .max_values = 4};
  EXPECT_FALSE(parse_json_bounded("[1,2,3]", limits).error);  // array + 3 numbers
  BoundedParse p = parse_json_bounded("[1,2,3,4]", limits);
  ASSERT_TRUE(p.error);
  EXPECT_EQ(p.error->code, "limit_exceeded");
  EXPECT_EQ(p.error->path, "/3");
}

TEST(BoundedJson, SameDocumentAsNlohmannsParser) {
  const std::string text =
      R"({"a": [1, -2, 3.5, 1e300, true, null, "x\u00e9"], "b": {"c": {}}, "a2": [], "b": 7})";
  BoundedParse p = parse_json_bounded(text, JsonLimits{});
  ASSERT_FALSE(p.error);
  EXPECT_EQ(p.value, json::parse(text));  // a repeated key: the last wins in both
}

TEST(BoundedJson, SyntaxErrorsAreOurWordsWithAPosition) {
  BoundedParse p = parse_json_bounded("{\"x\": [1,\n tru]}", JsonLimits{});
  ASSERT_TRUE(p.error);
  EXPECT_EQ(p.error->code, "bad_json");
  EXPECT_EQ(p.error->path, "/x/1");
  EXPECT_NE(p.error->message.find("line 2"), std::string::npos) << p.error->message;
  EXPECT_EQ(p.error->message.find("json.exception"), std::string::npos) << p.error->message;
  BoundedParse bad_utf8 = parse_json_bounded("{\"s\": \"\xff\"}", JsonLimits{});
  ASSERT_TRUE(bad_utf8.error);
  EXPECT_NE(bad_utf8.error->message.find("not UTF-8"), std::string::npos);
  BoundedParse cut = parse_json_bounded("{\"s\": [1, 2", JsonLimits{});
  ASSERT_TRUE(cut.error);
  EXPECT_NE(cut.error->message.find("ends before"), std::string::npos) << cut.error->message;
}

TEST(BoundedJson, OverflowingNumberNamesItsPathAndRecoversTheId) {
  BoundedParse p = parse_json_bounded(R"({"params": {"r": [0, 1e999]}, "z": 2e999, "id": "late"})",
                                      JsonLimits{}, /*recover_top_level_scalars=*/true);
  ASSERT_TRUE(p.error);
  EXPECT_EQ(p.error->code, "not_finite");
  EXPECT_EQ(p.error->path, "/params/r/1");
  EXPECT_NE(p.error->message.find("1e999"), std::string::npos);
  EXPECT_EQ(p.value.value("id", ""), "late");  // read past both overflows
}

TEST(BoundedJson, LongKeysDoNotMakeLongPaths) {
  const std::string key(5000, 'k');
  BoundedParse p = parse_json_bounded("{\"" + key + "\": {\"" + key + "\": tru}}", JsonLimits{});
  ASSERT_TRUE(p.error);
  EXPECT_LE(p.error->path.size(), kMaxErrorPathBytes);
}

TEST(Request, ErrorsEchoTheIdWhenItWasRead) {
  json id;
  try {
    parse_request(R"({"id": "d", "method": "ping", "params": )" + nested_objects(100) + "}", &id);
    FAIL() << "depth 102 must be refused";
  } catch (const ProtocolError& e) {
    EXPECT_EQ(e.info().code, "limit_exceeded");
  }
  EXPECT_EQ(id, "d");
}

TEST(Request, IntegralFloatIdsAndCharacterCount) {
  json id;
  EXPECT_EQ(parse_request(R"({"id": 7.0, "method": "ping"})", &id).id, 7);
  EXPECT_THROW(parse_request(R"({"id": 7.5, "method": "ping"})", &id), ProtocolError);
  std::string accented;
  for (int i = 0; i < 128; ++i) accented += "\xc3\xa9";  // 128 characters, 256 bytes
  EXPECT_EQ(parse_request(R"({"id": ")" + accented + R"(", "method": "ping"})", &id).id, accented);
  EXPECT_THROW(parse_request(R"({"id": ")" + accented + R"(x", "method": "ping"})", &id),
               ProtocolError);
}

TEST(Request, ParamsThatAreNotAnObjectAreInvalidParams) {
  json id;
  try {
    parse_request(R"({"id": 1, "method": "ping", "params": [1]})", &id);
    FAIL();
  } catch (const ProtocolError& e) {
    EXPECT_EQ(e.info().code, "invalid_params");
    EXPECT_EQ(e.info().path, "/params");
  }
}

// ---- Frame sizes (defects 2-4) ---------------------------------------------------

SceneLimits small_limits() {
  SceneLimits l;
  l.max_width = 256;
  l.max_height = 256;
  l.max_pixels = 2000;
  return l;
}

ErrorInfo camera_error(const json& entry, const SceneLimits& limits) {
  try {
    parse_camera_list(json::array({entry}), "/params/cameras", limits);
  } catch (const ProtocolError& e) {
    return e.info();
  }
  return {};
}

TEST(FrameSize, DefaultSizesAreChecked) {
  SceneLimits l = small_limits();
  l.max_pixels = 1 << 20;
  for (const json& cam : {json::object(), json{{"rig", "orbit"}, {"count", 1}},
                          json{{"rig", "cubemap"}}, json{{"rig", "stereo"}, {"target", {0, 0, -1}}}}) {
    const ErrorInfo e = camera_error(cam, l);
    EXPECT_EQ(e.code, "limit_exceeded") << cam.dump();
    EXPECT_EQ(e.path, "/params/cameras/0") << cam.dump();
    EXPECT_NE(e.message.find("(the default)"), std::string::npos) << e.message;
  }
}

TEST(FrameSize, CubemapIsCheckedAtItsSize) {
  const SceneLimits l = small_limits();
  const auto cams =
      parse_camera_list(json::array({{{"rig", "cubemap"}, {"size", 8}}}), "/params/cameras", l);
  EXPECT_EQ(cams.size(), 6u);
  const ErrorInfo e = camera_error({{"rig", "cubemap"}, {"size", 64}}, l);
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_EQ(e.path, "/params/cameras/0/size");
}

TEST(FrameSize, AtlasGridMatchesTheDocumentedLayout) {
  const AtlasGrid g = atlas_grid({{60, 60}, {60, 40}, {30, 60}, {10, 10}, {5, 5}});
  EXPECT_EQ(g.columns, 3);  // ceil(sqrt(5))
  EXPECT_EQ(g.rows, 2);
  EXPECT_EQ(g.width(), 180);
  EXPECT_EQ(g.height(), 120);
  try {
    check_frame_size(g.width(), g.height(), small_limits(), "/params/atlas", "/params/atlas",
                     "the atlas");
    FAIL() << "180 x 120 is over max_pixels 2000";
  } catch (const ProtocolError& e) {
    EXPECT_EQ(e.info().path, "/params/atlas");
  }
}

}  // namespace
}  // namespace beamcast
