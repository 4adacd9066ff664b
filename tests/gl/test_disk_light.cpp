// The "disk" light on the GPU: what a camera sees of it (the G-buffer's
// polygon, gi_resolve's outline antialiasing through the disk's branch of
// shaders/light_outline.glsl) against the share of each pixel the exact
// disk covers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "protocol/camera.hpp"
#include "protocol/scene_json.hpp"
#include "render/renderer.hpp"
#include "tests/common/outline_shares.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

// A disk light of radius 0.6 facing +z on a black wall, seen head-on by an
// orthographic camera and from off the axis by a perspective one (the
// outline an ellipse): each pixel should hold the radiance times the share
// of the pixel it covers (the reference's pixel average), here 32 x 32 rays
// a pixel met with the plane z = 0. Antialiased, an outline pixel's share
// is the count of its 4 x 4 rays that meet the disk.
TEST(DiskLightGl, OutlinesGetTheShareOfEachPixel) {
  constexpr double kL = 5.0, kR = 0.6, kCx = 0.1, kCy = -0.15;
  constexpr int kSize = 96;
  for (const bool perspective : {false, true}) {
    SCOPED_TRACE(perspective ? "perspective" : "orthographic");
    auto scene_json = [&](bool aa) {
      json cam = {{"position", {0, 0, 3}}, {"target", {0, 0, 0}}, {"projection", "orthographic"},
                  {"ortho_height", 2.0}, {"width", kSize}, {"height", kSize}};
      if (perspective) {
        cam = {{"position", {0.9, -0.7, 2.6}}, {"target", {0, 0, 0}}, {"fov_y", 40},
               {"width", kSize}, {"height", kSize}};
      }
      return json{{"occluders", {{{"type", "quad"}, {"corner", {-2, -2, -1}}, {"edge_u", {4, 0, 0}},
                                  {"edge_v", {0, 4, 0}}, {"albedo", {0, 0, 0}}}}},
                  {"lights", {{{"type", "disk"}, {"center", {kCx, kCy, 0}}, {"normal", {0, 0, 2}},
                               {"radius", kR}, {"radiance", {kL, kL, kL}}}}},
                  {"gi", {{"photons", 1000}, {"light_antialias", aa}}},
                  {"cameras", json::array({cam})}};
    };
    const Scene probe = parse_scene(scene_json(true), {});
    const std::vector<double> share =
        test::plane_z0_shares(probe.cameras[0], kSize, [&](double x, double y) {
          return (x - kCx) * (x - kCx) + (y - kCy) * (y - kCy) <= kR * kR;
        });
    Renderer renderer;
    double err[2] = {0.0, 0.0};
    for (int aa = 0; aa < 2; ++aa) {
      const auto frames =
          renderer.render(parse_scene(scene_json(aa == 1), {}), FrameOptions{.read_hdr = true});
      ASSERT_EQ(frames.size(), 1u);
      ASSERT_EQ(frames[0].hdr.rgb.size(), 3u * kSize * kSize);
      // Pixels mostly covered must not read under a fifth of their share. A
      // pixel whose centre is outside the exact disk is less than half
      // covered (a tangent line separates them); aliased, the centre is
      // tested against the G-buffer's 96-gon, up to 5.4e-4 R (1.6% of a
      // pixel here) inside the circle, so such a pixel counts from a
      // share of 0.6 (the 32 x 32 count itself rounds to 1/32 a side).
      const test::OutlineError e =
          test::outline_error(frames[0].hdr.rgb, share, kL, aa == 1 ? 0.5 : 0.6);
      err[aa] = e.relative_l1;
      EXPECT_EQ(e.lost, 0);
      std::printf("disk light outline (%s) %s: relative L1 %.4f\n",
                  perspective ? "perspective" : "orthographic", aa ? "antialiased" : "aliased",
                  err[aa]);
    }
    // About 110 outline pixels (circumference 2 pi 0.6 = 3.8 over pixels
    // of 2/96) against 2 500 inside. Antialiased, each outline pixel's share
    // is a 4 x 4 count (within 1/8 of the pixel on average along a curve,
    // where the sub-pixel steps do not line up): about 110 x 0.06 / 2 600
    // = 0.25% (measured 0.19% orthographic, 0.22% perspective), bound
    // 0.5%. Aliased, the outline pixels err by a quarter on average: about
    // 1% (measured 1.7%), so the antialiased error must be well under it.
    EXPECT_LT(err[1], 0.005);
    EXPECT_LT(err[1], 0.6 * err[0]);
  }
}

}  // namespace
}  // namespace beamcast
