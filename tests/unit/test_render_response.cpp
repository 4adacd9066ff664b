// protocol/render_response: the render result's wire format, both directions.
#include <gtest/gtest.h>

#include "protocol/errors.hpp"
#include "protocol/render_response.hpp"

namespace beamcast {
namespace {

using json = nlohmann::json;

// PROTOCOL.md's render result example and its "quality": "auto" block (budget_ms
// written 33.0: the server sends it as a double).
json protocol_example() {
  return json::parse(R"({"passes": ["beams", "tonemap"],
 "frames": [{"camera": "view", "index": 0, "width": 512, "height": 512, "format": "png", "bit_depth": 8,
             "attachment": {"offset": 0, "length": 48213},
             "gpu_ms": 3.1, "pass_ms": {"beams": 2.6, "tonemap": 0.5}, "readback_ms": 1.2, "encode_ms": 6.0,
             "gpu_batch": {"index": 0, "views": 1, "gpu_ms": 3.1, "readback_ms": 1.2}}],
 "batched": false,
 "batch": {"requests": 1, "views": 1},
 "timings": {"queue_ms": 0.1, "render_ms": 4.5, "readback_ms": 1.2, "encode_ms": 6.0, "server_ms": 11.9},
 "quality": {"mode": "auto", "level": 3, "levels": 5, "label": "table32x32@1/2",
            "reason": "moving", "still": false, "moving": true, "scale": 0.5,
            "method": "table", "table": [32, 32], "samples": 64, "format": "jpeg", "jpeg_quality": 80,
            "budget_ms": 33.0, "estimate_ms": 21.4, "frame_ms": 19.8}})");
}

// PROTOCOL.md's atlas example, completed with the fields every result has.
json atlas_example() {
  return json::parse(R"({"passes": ["beams", "tonemap"], "batched": false,
 "batch": {"requests": 1, "views": 6},
 "timings": {"queue_ms": 0.1, "render_ms": 4.5, "readback_ms": 1.2, "encode_ms": 9.5, "server_ms": 15.0},
 "frames": [{"camera": "atlas", "index": 0, "width": 768, "height": 512, "format": "png", "bit_depth": 8,
             "data_base64": "iVBORw0KGgo=", "encode_ms": 9.5,
             "atlas": {"columns": 3, "rows": 2, "cell_width": 256, "cell_height": 256,
                       "tiles": [{"camera": "env_px", "index": 0, "x": 0, "y": 0, "width": 256, "height": 256,
                                  "gpu_ms": 20.1, "pass_ms": {"beams": 20.1}, "readback_ms": 0.2,
                                  "gpu_batch": {"index": 0, "views": 4, "gpu_ms": 80.4, "readback_ms": 0.8}}]}}]})");
}

TEST(RenderResponse, ProtocolExampleRoundTrips) {
  for (const json& j : {protocol_example(), atlas_example()}) {
    const RenderResponse r = render_response_from_json(j);
    EXPECT_EQ(to_json(r), j);
    EXPECT_EQ(to_json(r).dump(), j.dump());  // same keys and number types on the wire
    EXPECT_EQ(render_response_from_json(to_json(r)), r);
  }
}

TEST(RenderResponse, ReadsTheExampleFields) {
  const RenderResponse r = render_response_from_json(protocol_example());
  ASSERT_EQ(r.frames.size(), 1u);
  const RenderFrame& f = r.frames[0];
  EXPECT_EQ(f.camera, "view");
  EXPECT_EQ(f.attachment, (Attachment{0, 48213}));
  EXPECT_FALSE(f.data_base64);
  EXPECT_EQ(f.pass_ms, (std::vector<PassTime>{{"beams", 2.6}, {"tonemap", 0.5}}));
  EXPECT_EQ(f.gpu_batch, (GpuBatch{0, 1, 3.1, 1.2}));
  EXPECT_EQ(r.passes, (std::vector<std::string>{"beams", "tonemap"}));
  EXPECT_EQ(r.timings.server_ms, 11.9);
  ASSERT_TRUE(r.quality);
  EXPECT_EQ(r.quality->table, (std::array<int, 2>{32, 32}));
  EXPECT_EQ(r.quality->jpeg_quality, 80);

  const RenderResponse a = render_response_from_json(atlas_example());
  ASSERT_TRUE(a.frames[0].atlas);
  EXPECT_FALSE(a.frames[0].gpu_ms);
  EXPECT_EQ(a.frames[0].atlas->tiles[0].x, 0);
  EXPECT_FALSE(a.frames[0].atlas->tiles[0].format);
}

// A streamed part (PROTOCOL.md, "Streaming"): "stream" round-trips, and a bad
// field in it names its pointer.
TEST(RenderResponse, StreamPartRoundTrips) {
  json j = protocol_example();
  j["stream"] = {{"part", 2}, {"last", false}, {"frames", 16}};
  const RenderResponse r = render_response_from_json(j);
  EXPECT_EQ(r.stream, (StreamPart{2, false, 16}));
  EXPECT_EQ(to_json(r), j);
  EXPECT_FALSE(render_response_from_json(protocol_example()).stream);
  j["stream"]["last"] = "no";
  try {
    render_response_from_json(j, "/result");
    FAIL() << "a non-boolean stream.last was accepted";
  } catch (const ProtocolError& e) {
    EXPECT_EQ(e.info().path, "/result/stream/last");
  }
}

TEST(RenderResponse, UnknownKeysAreIgnored) {
  json j = protocol_example();
  j["added_later"] = {1, 2};
  j["frames"][0]["added_later"] = "x";
  j["timings"]["gpu_wait_ms"] = 1.0;
  EXPECT_EQ(to_json(render_response_from_json(j)), protocol_example());
}

// Every bad or missing field is reported at its own pointer.
TEST(RenderResponse, BadFieldsNameTheirPointer) {
  const struct {
    const char* pointer;
    json value;  // null: remove the field
    const char* code;
  } cases[] = {
      {"/frames", nullptr, "missing_field"},
      {"/frames", json::object(), "wrong_type"},
      {"/frames/0/width", "512", "wrong_type"},
      {"/frames/0/width", 1e12, "out_of_range"},
      {"/frames/0/camera", nullptr, "missing_field"},
      {"/frames/0/attachment/offset", -1, "out_of_range"},
      {"/frames/0/pass_ms/beams", "fast", "wrong_type"},
      {"/frames/0/gpu_batch/views", nullptr, "missing_field"},
      {"/timings/server_ms", nullptr, "missing_field"},
      {"/batch", 1, "wrong_type"},
      {"/quality/table", json::array({32}), "wrong_type"},
      {"/quality/still", 0, "wrong_type"},
  };
  for (const auto& c : cases) {
    json j = protocol_example();
    const json::json_pointer p(c.pointer);
    if (c.value.is_null()) {
      j[p.parent_pointer()].erase(p.back());
    } else {
      j[p] = c.value;
    }
    try {
      render_response_from_json(j, "/result");
      ADD_FAILURE() << c.pointer << ": accepted";
    } catch (const ProtocolError& e) {
      EXPECT_EQ(e.info().path, std::string("/result") + c.pointer) << e.what();
      EXPECT_EQ(e.info().code, c.code) << e.what();
    }
  }
}

}  // namespace
}  // namespace beamcast
