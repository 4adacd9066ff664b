// server/render_result: the render response built from a hand-made outcome
// (no GL, no server).
#include <gtest/gtest.h>

#include "protocol/base64.hpp"
#include "server/render_result.hpp"

namespace beamcast {
namespace {

FrameResult frame(double gpu_ms, int batch_index, int views) {
  FrameResult f;
  f.passes = {{"beams", gpu_ms * 0.75}, {"tonemap", gpu_ms * 0.25}};
  f.gpu_ms = gpu_ms;
  f.readback_ms = 0.5 * gpu_ms;
  f.batch = BatchTiming{batch_index, views, gpu_ms * views, 0.5 * gpu_ms * views, 0.0, {}};
  return f;
}

Camera camera(std::string name, int w, int h) {
  Camera c;
  c.name = std::move(name);
  c.width = w;
  c.height = h;
  return c;
}

// Three cameras (the second unnamed), two of them in one GPU batch.
RenderOutcome outcome() {
  RenderOutcome out;
  out.frames = {frame(2.0, 0, 2), frame(4.0, 0, 2), frame(8.0, 1, 1)};
  out.pngs = {{1, 2, 3}, {4, 5}, {6, 7, 8, 9}};
  out.is_jpeg = {0, 1, 0};
  out.encode_ms = {1.0, 2.0, 3.0};
  out.queue_ms = 0.25;
  out.render_ms = 20.0;
  out.encode_wall_ms = 3.5;
  out.batched_requests = 1;
  out.batched_views = 3;
  return out;
}

RenderResultContext context() {
  RenderResultContext ctx;
  ctx.cameras = {camera("a", 64, 32), camera("", 64, 32), camera("c", 16, 16)};
  ctx.planned_passes = {"beams", "tonemap"};
  ctx.bit_depth = 16;
  ctx.server_ms = 30.0;
  return ctx;
}

TEST(RenderResult, FrameFieldsFromTheOutcome) {
  std::vector<std::uint8_t> binary;
  const RenderResponse r = build_render_response(outcome(), context(), &binary);
  ASSERT_EQ(r.frames.size(), 3u);
  const RenderFrame& f1 = r.frames[1];
  EXPECT_EQ(f1.camera, "camera_1");  // unnamed: named after its index
  EXPECT_EQ(f1.index, 1u);
  EXPECT_EQ(f1.width, 64);
  EXPECT_EQ(f1.height, 32);
  EXPECT_EQ(f1.gpu_ms, 4.0);
  EXPECT_EQ(f1.pass_ms, (std::vector<PassTime>{{"beams", 3.0}, {"tonemap", 1.0}}));
  EXPECT_EQ(f1.readback_ms, 2.0);
  EXPECT_EQ(f1.gpu_batch, (GpuBatch{0, 2, 8.0, 4.0}));
  EXPECT_EQ(f1.format, "jpeg");
  EXPECT_EQ(f1.bit_depth, 8);  // JPEG: 8 bits whatever the scene's bit depth
  EXPECT_EQ(r.frames[0].bit_depth, 16);
  EXPECT_EQ(r.frames[2].format, "png");
  EXPECT_EQ(f1.encode_ms, 2.0);
  EXPECT_FALSE(f1.x);
  EXPECT_FALSE(f1.atlas);
  EXPECT_EQ(r.passes, (std::vector<std::string>{"beams", "tonemap"}));
  EXPECT_FALSE(r.batched);
  EXPECT_EQ(r.batch_views, 3);
  // readback_ms is the sum of the frames' shares: 1 + 2 + 4 (exact in binary).
  EXPECT_EQ(r.timings, (RenderTimings{0.25, 20.0, 7.0, 3.5, 30.0}));
  EXPECT_FALSE(r.quality);
}

TEST(RenderResult, AttachmentsPointIntoTheBinarySection) {
  std::vector<std::uint8_t> binary = {0xAA};  // already holding bytes: offsets follow them
  const RenderResponse r = build_render_response(outcome(), context(), &binary);
  EXPECT_EQ(binary, (std::vector<std::uint8_t>{0xAA, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
  const RenderOutcome out = outcome();
  for (std::size_t i = 0; i < r.frames.size(); ++i) {
    ASSERT_TRUE(r.frames[i].attachment);
    EXPECT_FALSE(r.frames[i].data_base64);
    const Attachment& a = *r.frames[i].attachment;
    EXPECT_EQ(
        std::vector<std::uint8_t>(binary.begin() + a.offset, binary.begin() + a.offset + a.length),
        out.pngs[i]);
  }
}

TEST(RenderResult, Base64LeavesTheBinarySectionEmpty) {
  RenderResultContext ctx = context();
  ctx.base64 = true;
  std::vector<std::uint8_t> binary;
  const RenderResponse r = build_render_response(outcome(), ctx, &binary);
  EXPECT_TRUE(binary.empty());
  const RenderOutcome out = outcome();
  for (std::size_t i = 0; i < r.frames.size(); ++i) {
    EXPECT_FALSE(r.frames[i].attachment);
    ASSERT_TRUE(r.frames[i].data_base64);
    EXPECT_EQ(base64_decode(*r.frames[i].data_base64), out.pngs[i]);
  }
}

TEST(RenderResult, AtlasFramesBecomeTiles) {
  RenderOutcome out = outcome();
  out.is_jpeg = {0};
  out.encode_ms = {5.0};
  out.pngs = {{42, 43}};
  Atlas atlas;
  atlas.columns = 2;
  atlas.rows = 2;
  atlas.cell_width = 64;
  atlas.cell_height = 32;
  atlas.tiles = {{0, 0, 64, 32}, {64, 0, 64, 32}, {0, 32, 16, 16}};
  out.atlas = std::move(atlas);
  std::vector<std::uint8_t> binary;
  const RenderResponse r = build_render_response(out, context(), &binary);
  ASSERT_EQ(r.frames.size(), 1u);
  const RenderFrame& f = r.frames[0];
  EXPECT_EQ(f.camera, "atlas");
  EXPECT_EQ(f.width, 128);
  EXPECT_EQ(f.height, 64);
  EXPECT_EQ(f.bit_depth, 16);
  EXPECT_EQ(f.encode_ms, 5.0);
  EXPECT_EQ(f.attachment, (Attachment{0, 2}));
  EXPECT_FALSE(f.gpu_ms);  // timings are the tiles'
  EXPECT_EQ(binary, (std::vector<std::uint8_t>{42, 43}));
  ASSERT_TRUE(f.atlas);
  ASSERT_EQ(f.atlas->tiles.size(), 3u);
  const RenderFrame& t = f.atlas->tiles[2];
  EXPECT_EQ(t.camera, "c");
  EXPECT_EQ(t.x, 0);
  EXPECT_EQ(t.y, 32);
  EXPECT_EQ(t.gpu_ms, 8.0);
  EXPECT_FALSE(t.format);
  EXPECT_FALSE(t.attachment);
  EXPECT_EQ(f.atlas->tiles[1].x, 64);
}

TEST(RenderResult, NoFramesReportThePlannedPasses) {
  RenderOutcome out;
  RenderResultContext ctx = context();
  ctx.cameras.clear();
  ctx.planned_passes = {"surfaces", "tonemap"};
  std::vector<std::uint8_t> binary;
  EXPECT_EQ(build_render_response(out, ctx, &binary).passes, ctx.planned_passes);
}

TEST(RenderResult, QualityBlock) {
  ControllerDecision d;
  d.level = 3;
  d.reason = "moving";
  d.moving = true;
  d.estimate_ms = 21.5;
  AccuracyLevel level;
  level.label = "table32x32@1/2";
  level.scale = 0.5;
  level.render.method = IntegrationMethod::kTable;
  level.render.table_d = 32;
  level.render.table_s = 32;
  level.render.samples = 64;
  const QualityReport q = quality_report(d, level, 5, 33.0, true, 80, 19.75);
  EXPECT_EQ(q.mode, "auto");
  EXPECT_EQ(q.level, 3u);
  EXPECT_EQ(q.levels, 5u);
  EXPECT_EQ(q.method, "table");
  EXPECT_EQ(q.table, (std::array<int, 2>{32, 32}));
  EXPECT_EQ(q.scale, 0.5);
  EXPECT_EQ(q.format, "jpeg");
  EXPECT_EQ(q.jpeg_quality, 80);
  EXPECT_EQ(q.frame_ms, 19.75);
  // A still frame: full scale, PNG, no JPEG quality.
  d.still = true;
  level.render.method = IntegrationMethod::kClosedForm;
  const QualityReport s = quality_report(d, level, 5, 33.0, false, 80, 19.75);
  EXPECT_EQ(s.scale, 1.0);
  EXPECT_EQ(s.format, "png");
  EXPECT_FALSE(s.jpeg_quality);
  EXPECT_EQ(s.method, "closed_form");
  // The response carries the block as given.
  RenderResultContext ctx = context();
  ctx.quality = q;
  std::vector<std::uint8_t> binary;
  EXPECT_EQ(build_render_response(outcome(), ctx, &binary).quality, q);
}

}  // namespace
}  // namespace beamcast
