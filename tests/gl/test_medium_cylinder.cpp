// The "cylinder" medium region on the GPU (shaders/medium_regions.glsl)
// against the CPU reference (its exact chords in double, render/reference.hpp).
#include <gtest/gtest.h>

#include <cstdio>

#include "protocol/scene_json.hpp"
#include "render/image.hpp"
#include "render/reference.hpp"
#include "render/renderer.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

// Surfaces and the background seen through a cylinder of fog at 64x64: the
// optical depth is a sum of chords, so the GPU's image (float) matches the
// reference's within 2e-3 relative L1, the bound of the box and sphere
// regions (Medium.RegionsAttenuateSurfacesExactlyAndBeamsClosely). Three
// views: oblique from outside; from inside, along the axis (the rays
// nearly parallel to it); and across a thin cylinder, so most of the
// covered pixels' rays cross its side near a tangent.
TEST(MediumCylinder, AttenuatesSurfacesAsTheReference) {
  struct View {
    json region;
    Vec3 eye, target;
  };
  const View views[] = {
      {{{"type", "cylinder"}, {"p0", {-2.0, -1.0, -0.5}}, {"p1", {2.0, 1.2, 1.0}},
        {"radius", 1.1}, {"sigma_a", 0.6}},
       {0.5, 1.0, 7.0}, {0, 0, 0}},
      {{{"type", "cylinder"}, {"p0", {0.0, 0.0, 9.0}}, {"p1", {0.0, 0.0, -1.0}},
        {"radius", 1.5}, {"sigma_a", 0.3}},
       {0.2, -0.1, 7.0}, {0.0, 0.0, 0.0}},
      {{{"type", "cylinder"}, {"p0", {-4.0, 0.3, 0.0}}, {"p1", {4.0, -0.2, 0.5}},
        {"radius", 0.25}, {"sigma_s", 2.0}, {"sigma_a", 1.0}},
       {0.0, 0.5, 6.0}, {0, 0, 0}},
  };
  Renderer renderer;
  for (const View& view : views) {
    const json j = {
        {"background", {0.2, 0.4, 0.6}},
        {"occluders",
         {{{"type", "sphere"}, {"center", {1.0, -0.8, 0.3}}, {"radius", 0.7}},
          {{"type", "plane"}, {"point", {0, 0, -3}}, {"normal", {0, 0, 1}}}}},
        {"media", json::array({view.region})},
        {"cameras",
         {{{"position", {view.eye[0], view.eye[1], view.eye[2]}},
           {"target", {view.target[0], view.target[1], view.target[2]}},
           {"width", 64},
           {"height", 64}}}}};
    const Scene scene = parse_scene(j, {});
    const HdrImage ref = render_reference(scene, scene.cameras[0]);
    const auto frames = renderer.render(scene, FrameOptions{.read_hdr = true});
    const HdrError e = compare_hdr(frames[0].hdr, ref);
    std::printf("cylinder region: rel L1 %.2e, max abs %.2e\n", e.rel_l1, e.max_abs);
    EXPECT_EQ(e.nonfinite, 0) << view.region.dump();
    EXPECT_LT(e.rel_l1, 2e-3) << view.region.dump();
  }
}

}  // namespace
}  // namespace beamcast
