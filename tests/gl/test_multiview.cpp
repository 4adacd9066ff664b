// Multi-view batches against one camera at a time: for every rig type and for
// explicit cameras of mixed sizes, the frames of one K-camera render must equal
// the K frames rendered singly.
//
// Tolerance: none. Both paths run the same shader source (the multi-view
// variant only selects the camera block, the beam and occluder copies and the
// texture layer by the uniform view index), fed the same float values computed
// by the same CPU code (SceneResources::fill_*), and rasterize the same
// triangles at the same viewport size, so every fragment does the same float
// operations; the 8-bit frames and the HDR buffers are compared bit for bit.
// (Were a driver to contract multiply-adds differently between the two
// programs, this test is where it would show, and a tolerance would have to
// be argued for then.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <set>
#include <string>

#include "protocol/scene_json.hpp"
#include "render/renderer.hpp"

namespace beamcast {
namespace {

Renderer& renderer() {
  static std::unique_ptr<Renderer> r = std::make_unique<Renderer>();
  return *r;
}

// Beams of both kinds and every occluder kind that has its own code path
// (rasterized box, ray-traced plane and sphere), so every pass runs.
nlohmann::json scene_with(const nlohmann::json& cameras) {
  return {{"beams",
           {{{"type", "sphere"}, {"center", {0, 0.5, 0}}, {"radius", 1.0}, {"density", "abe"}},
            {{"type", "capsule"},
             {"p0", {-1.5, 0, -1}},
             {"p1", {1.5, 0.3, 1}},
             {"radius", 0.4},
             {"density", "shell"},
             {"color", {1, 0.5, 0.2}}}}},
          {"occluders",
           {{{"type", "box"}, {"center", {0.8, -0.4, 0.8}}, {"size", {0.6, 0.6, 0.6}}},
            {{"type", "plane"}, {"point", {0, -1.2, 0}}, {"normal", {0, 1, 0}}},
            {{"type", "sphere"}, {"center", {-1.2, 0.9, 0.4}}, {"radius", 0.35}}}},
          {"cameras", cameras}};
}

// Renders `cameras_json` batched and one camera at a time and compares.
void expect_batched_equals_single(const nlohmann::json& cameras_json, std::size_t expect_views,
                                  int expect_batches) {
  const Scene scene = parse_scene(scene_with(cameras_json), SceneLoadOptions{});
  ASSERT_EQ(scene.cameras.size(), expect_views);
  // Larger batches than the default, so every rig is one batch.
  const auto batched = renderer().render(
      scene, FrameOptions{.read_hdr = true, .batch = true, .max_batch_views = 64});
  const auto single = renderer().render(scene, FrameOptions{.read_hdr = true, .batch = false});
  ASSERT_EQ(batched.size(), expect_views);
  ASSERT_EQ(single.size(), expect_views);
  std::set<int> batch_ids;
  std::set<std::vector<std::uint16_t>> distinct;
  for (std::size_t i = 0; i < expect_views; ++i) {
    SCOPED_TRACE("camera " + std::to_string(i) + " " + scene.cameras[i].name);
    const FrameResult& b = batched[i];
    const FrameResult& s = single[i];
    batch_ids.insert(b.batch.index);
    EXPECT_EQ(s.batch.views, 1);
    ASSERT_EQ(b.image.width, scene.cameras[i].width);
    ASSERT_EQ(b.image.height, scene.cameras[i].height);
    ASSERT_EQ(b.image.rgb.size(), s.image.rgb.size());
    std::size_t differ = 0;
    for (std::size_t k = 0; k < b.image.rgb.size(); ++k) differ += b.image.rgb[k] != s.image.rgb[k];
    EXPECT_EQ(differ, 0u) << "8-bit channel values that differ, of " << b.image.rgb.size();
    ASSERT_EQ(b.hdr.rgb.size(), s.hdr.rgb.size());
    EXPECT_EQ(std::memcmp(b.hdr.rgb.data(), s.hdr.rgb.data(), b.hdr.rgb.size() * sizeof(float)),
              0)
        << "HDR buffers differ";
    distinct.insert(b.image.rgb);
  }
  EXPECT_EQ(static_cast<int>(batch_ids.size()), expect_batches);
  // The views really differ (a batch that drew view 0 into every layer would
  // have been caught above, but a rig that put every camera in one place not).
  // Not all K: views that see only background, or only the underside of the
  // plane (uniformly lit), legitimately coincide.
  EXPECT_GE(distinct.size(), std::min<std::size_t>(expect_views, 3));
}

TEST(MultiView, OrbitCircleBatchEqualsSingleRenders) {
  expect_batched_equals_single(
      {{{"rig", "orbit"}, {"count", 6}, {"radius", 6}, {"elevation", 20}, {"width", 64},
        {"height", 48}}},
      6, 1);
}

TEST(MultiView, OrbitSphereBatchEqualsSingleRenders) {
  expect_batched_equals_single(
      {{{"rig", "orbit"}, {"layout", "sphere"}, {"count", 5}, {"radius", 5},
        {"target", {0, 0.2, 0}}, {"width", 56}, {"height", 56}}},
      5, 1);
}

TEST(MultiView, CubemapBatchEqualsSingleRenders) {
  // From inside the scene, between the beams: every face sees something.
  expect_batched_equals_single(
      {{{"rig", "cubemap"}, {"position", {0.3, 0.2, 2.5}}, {"size", 48}}}, 6, 1);
}

TEST(MultiView, StereoBatchEqualsSingleRenders) {
  expect_batched_equals_single({{{"rig", "stereo"},
                                 {"position", {0, 1, 6}},
                                 {"target", {0, 0, 0}},
                                 {"eye_separation", 0.3},
                                 {"width", 64},
                                 {"height", 64}}},
                               2, 1);
}

TEST(MultiView, MixedSizesAreGroupedAndKeepTheirOrder) {
  // Two sizes interleaved, plus an orthographic camera: two batches (3 + 2
  // views), frames returned in camera order.
  expect_batched_equals_single(
      {{{"position", {0, 1, 6}}, {"target", {0, 0, 0}}, {"width", 40}, {"height", 40}},
       {{"position", {5, 1, 2}}, {"target", {0, 0, 0}}, {"width", 48}, {"height", 32}},
       {{"position", {-4, 2, 4}}, {"target", {0, 0, 0}}, {"width", 40}, {"height", 40}},
       {{"position", {0, 6, 1}}, {"target", {0, 0, 0}}, {"width", 48}, {"height", 32},
        {"projection", "orthographic"}, {"ortho_height", 5}},
       {{"position", {-5, 0.5, -3}}, {"target", {0, 0, 0}}, {"width", 40}, {"height", 40}}},
      5, 2);
}

TEST(MultiView, BatchesSplitAtTheViewBound) {
  const Scene scene = parse_scene(
      scene_with({{{"rig", "orbit"}, {"count", 5}, {"width", 32}, {"height", 32}}}),
      SceneLoadOptions{});
  const auto frames = renderer().render(scene, FrameOptions{.max_batch_views = 2});
  ASSERT_EQ(frames.size(), 5u);
  // 2 + 2 + 1 views.
  const int views[5] = {2, 2, 2, 2, 1};
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(frames[i].batch.views, views[i]) << i;
    EXPECT_EQ(frames[i].batch.index, static_cast<int>(i / 2)) << i;
  }
}

// Without the HDR read-back, batch k's read-back is finished only after batch
// k+1's passes are submitted (pixel buffer objects, render/renderer.cpp): the
// frames must still be those of single renders, bit for bit (as must those of
// the synchronous read-back, Readback::kSynchronous), at 8 and 16 bits,
// also when the targets change size between two batches and when a one-view
// batch (the per-camera path) comes between two; and each frame's timing split
// must add up.
TEST(MultiView, PipelinedReadBackEqualsSingleRenders) {
  for (int bits : {8, 16}) {
    SCOPED_TRACE("bit depth " + std::to_string(bits));
    nlohmann::json j = scene_with(
        {{{"rig", "orbit"}, {"count", 5}, {"radius", 6}, {"width", 40}, {"height", 40}},
         {{"position", {5, 1, 2}}, {"target", {0, 0, 0}}, {"width", 48}, {"height", 32}},
         {{"position", {-4, 2, 4}}, {"target", {0, 0, 0}}, {"width", 48}, {"height", 32}},
         {{"rig", "orbit"}, {"name", "high"}, {"count", 3}, {"radius", 5}, {"elevation", 30},
          {"width", 40}, {"height", 40}},
         {{"position", {0, 6, 1}}, {"target", {0, 0, 0}}, {"width", 32}, {"height", 32}},
         {{"position", {-5, 0.5, -3}}, {"target", {0, 0, 0}}, {"width", 24}, {"height", 24}},
         {{"position", {0, 1, 6}}, {"target", {0, 0, 0}}, {"width", 24}, {"height", 24}}});
    j["output"] = {{"bit_depth", bits}};
    const Scene scene = parse_scene(j, SceneLoadOptions{});
    ASSERT_EQ(scene.cameras.size(), 13u);
    // Batches in order: 40x40 2+2+2+2, 48x32 2 (new target size while the
    // last 40x40 read-back is pending), 32x32 alone (per-camera path), 24x24 2.
    const auto single = renderer().render(scene, FrameOptions{.batch = false});
    for (bool pipelined : {true, false}) {
      SCOPED_TRACE(pipelined ? "pipelined read-back" : "synchronous read-back");
      const auto batched = renderer().render(
          scene, FrameOptions{.max_batch_views = 2,
                              .readback = pipelined ? Readback::kPipelined
                                                    : Readback::kSynchronous});
      ASSERT_EQ(batched.size(), 13u);
      std::set<int> batch_ids;
      for (std::size_t i = 0; i < batched.size(); ++i) {
        SCOPED_TRACE("camera " + std::to_string(i));
        const FrameResult& b = batched[i];
        batch_ids.insert(b.batch.index);
        EXPECT_EQ(b.image.bit_depth, bits);
        ASSERT_EQ(b.image.width, scene.cameras[i].width);
        ASSERT_EQ(b.image.height, scene.cameras[i].height);
        EXPECT_TRUE(b.image.rgb == single[i].image.rgb) << "frame differs from its single render";
        // readback = wait + copy (the single-camera path counts it all as wait).
        EXPECT_DOUBLE_EQ(b.batch.readback_ms, b.batch.readback_wait_ms + b.batch.readback_copy_ms);
        EXPECT_GT(b.batch.submit_ms, 0.0);
        if (b.batch.views > 1) {
          EXPECT_DOUBLE_EQ(b.batch.wall_ms, b.batch.submit_ms + b.batch.readback_ms);
        }
      }
      EXPECT_EQ(batch_ids.size(), 7u);
    }
  }
}

}  // namespace
}  // namespace beamcast
