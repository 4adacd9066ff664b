// Beams and surfaces seen through a homogeneous medium (issue 15, item 4) on
// the GPU against the CPU reference, which integrates f e^(-sigma_t t) along
// each ray by adaptive quadrature in double (render/reference.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "protocol/scene_json.hpp"
#include "render/image.hpp"
#include "render/reference.hpp"
#include "render/renderer.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

Renderer& renderer() {
  static Renderer r;
  return r;
}

// Unit-radius beams of four densities and a capsule seen obliquely, a
// sphere occluder cutting into the capsule, at 96x96: sigma_t is sigma_t r.
json beams_in_fog(double sigma_t, json medium_extra = json::object()) {
  json medium = {{"sigma_a", sigma_t}};
  medium.update(medium_extra);
  return {{"beams",
           {{{"type", "sphere"}, {"center", {-2.4, 1.2, 0}}, {"radius", 1.0},
             {"density", "quadratic"}},
            {{"type", "sphere"}, {"center", {0, 1.2, 0}}, {"radius", 1.0}, {"density", "shell"}},
            {{"type", "sphere"}, {"center", {2.4, 1.2, 0}}, {"radius", 1.0}, {"density", "abe"}},
            {{"type", "capsule"},
             {"p0", {-2.5, -1.4, -1.5}},
             {"p1", {2.5, -1.2, 1.0}},
             {"radius", 0.8},
             {"density", "gaussian"}}}},
          {"occluders", {{{"type", "sphere"}, {"center", {1.5, -1.3, 0.5}}, {"radius", 0.6}}}},
          {"medium", medium},
          {"cameras",
           {{{"position", {0.5, 1.0, 7.0}}, {"target", {0, 0, 0}}, {"width", 96},
             {"height", 96}}}}};
}

HdrError against_reference(const json& j) {
  const Scene scene = parse_scene(j, {});
  const HdrImage ref = render_reference(scene, scene.cameras[0]);
  const auto frames = renderer().render(scene, FrameOptions{.read_hdr = true});
  return compare_hdr(frames[0].hdr, ref);
}

// The default rule against the exact attenuated integral. Without a medium
// the default table's image error on these densities is at most ~3e-4
// (docs/accuracy.md); the rule adds at most 1e-3 of a piece's light where
// sigma_t r <= 1 (unit test BeamMedium.TheRenderersRuleIsWithin1e3...),
// and far less on average over a pixel's pieces, so 1.5e-3 bounds the
// image's relative L1 there. At sigma_t r = 3 the rule's worst piece is a
// few 1e-3 (docs/media.md), 5e-3.
TEST(Medium, BeamsThroughFogMatchTheReference) {
  for (double sr : {0.01, 0.1, 1.0, 3.0}) {
    const HdrError e = against_reference(beams_in_fog(sr));
    std::printf("sigma_t r %-5g  rel L1 %.3e  max abs %.3e\n", sr, e.rel_l1, e.max_abs);
    EXPECT_EQ(e.nonfinite, 0);
    EXPECT_LT(e.rel_l1, sr <= 1.0 ? 1.5e-3 : 5e-3) << "sigma_t r " << sr;
  }
}

// The midpoint form (one piece per beam: step 8) is what the default's
// two-node rule improves on: several times the error at sigma_t r = 1.
TEST(Medium, TheMidpointFormIsWorseThanTheDefault) {
  const double gauss = against_reference(beams_in_fog(1.0)).rel_l1;
  const double midpoint =
      against_reference(beams_in_fog(1.0, {{"beam_rule", "midpoint"}, {"beam_step", 8.0}}))
          .rel_l1;
  std::printf("sigma_t r 1: gauss2 %.3e, midpoint one piece %.3e\n", gauss, midpoint);
  EXPECT_GT(midpoint, 3.0 * gauss);
}

// The march method puts e^(-sigma_t t) into its integrand: it converges to
// the same reference.
TEST(Medium, MarchingIncludesTheAttenuation) {
  json j = beams_in_fog(1.0);
  j["render"] = {{"method", "march"}, {"samples", 512}};
  const HdrError e = against_reference(j);
  EXPECT_EQ(e.nonfinite, 0);
  EXPECT_LT(e.rel_l1, 2e-3);  // the midpoint march's own error at N = 512 (test_methods)
}

// Hard cases stay finite: the camera inside a beam in thick fog, a ray
// along a capsule's axis, optical depths from 1e-6 to 1e3 per radius.
TEST(Medium, HardCasesStayFinite) {
  for (double sr : {1e-6, 10.0, 1e3}) {
    json j = beams_in_fog(sr);
    j["cameras"] = {{{"position", {0, 1.2, 0.3}}, {"target", {0, 1.2, -5}}, {"width", 48},
                     {"height", 48}},
                    {{"position", {-6.0, -1.4 - 0.2 * 3.5 / 5.0, -1.5 - 2.5 * 3.5 / 5.0}},
                     {"target", {2.5, -1.2, 1.0}}, {"width", 48}, {"height", 48}}};
    const Scene scene = parse_scene(j, {});
    for (const FrameResult& f : renderer().render(scene, FrameOptions{.read_hdr = true})) {
      for (float v : f.hdr.rgb) ASSERT_TRUE(std::isfinite(v)) << "sigma_t r " << sr;
    }
  }
}

// A surface in fog keeps e^(-sigma_t t) of its light; the background none.
TEST(Medium, SurfacesAreAttenuatedAndTheBackgroundVanishes) {
  json j = beams_in_fog(0.3);
  j["beams"] = json::array();
  j["background"] = {0.2, 0.4, 0.6};
  const HdrError e = against_reference(j);
  EXPECT_EQ(e.nonfinite, 0);
  // Float against double and the rasterized sphere's silhouette pixels.
  EXPECT_LT(e.rel_l1, 2e-3);
  const Scene scene = parse_scene(j, {});
  const auto frames = renderer().render(scene, FrameOptions{.read_hdr = true});
  EXPECT_EQ(frames[0].hdr.rgb[0], 0.0f);  // a corner: background only
}

}  // namespace
}  // namespace beamcast
