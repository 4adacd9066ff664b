// The "specular" pass traced on the GPU (issue 39, item 4;
// render/specular_gpu.hpp, shaders/specular_trace.comp) against the CPU
// tracer it replaces (LitShading with Embree and kd-trees, the reference):
// the same frame both ways on the same cached photon maps.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>

#include "gi/photon_cache.hpp"
#include "protocol/camera.hpp"
#include "protocol/scene_json.hpp"
#include "render/egl_context.hpp"
#include "render/pass_plan.hpp"
#include "render/renderer.hpp"
#include "render/scene_resources.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

Renderer& renderer() {
  static std::unique_ptr<Renderer> r = std::make_unique<Renderer>();
  return *r;
}

struct Difference {
  double rel_l1 = 0.0;        // sum |gpu - cpu| / sum cpu over the pixels the pass shows
  double far_share = 0.0;     // share of those pixels off by more than 5% (and 1e-3)
  std::size_t pixels = 0;     // pixels the specular pass shows (nonzero difference to "off")
};

// Renders `j` with gi.specular_tracer "gpu" and "cpu" and compares them over
// `mask` (specular_pixels: what the pass shows; the other pixels' passes
// are the same in both frames).
Difference compare(json j, const std::vector<bool>& mask) {
  HdrImage frames[2];
  for (int k = 0; k < 2; ++k) {
    j["gi"]["specular_tracer"] = k == 0 ? "gpu" : "cpu";
    const Scene scene = parse_scene(j, {});
    auto result = renderer().render(scene, FrameOptions{.read_hdr = true});
    frames[k] = std::move(result[0].hdr);
  }
  Difference d;
  double diff = 0.0, total = 0.0;
  std::size_t far = 0;
  for (std::size_t i = 0; i < mask.size(); ++i) {
    if (!mask[i]) continue;
    ++d.pixels;
    bool off = false;
    for (std::size_t c = 0; c < 3; ++c) {
      const double g = frames[0].rgb[3 * i + c], r = frames[1].rgb[3 * i + c];
      diff += std::abs(g - r);
      total += std::abs(r);
      off = off || std::abs(g - r) > std::max(0.05 * std::abs(r), 1e-3);
    }
    far += off ? 1 : 0;
  }
  d.rel_l1 = total > 0.0 ? diff / total : 0.0;
  d.far_share = d.pixels ? static_cast<double>(far) / static_cast<double>(d.pixels) : 0.0;
  return d;
}

// Pixels (rows top-down, as HdrImage) whose centre ray's nearest occluder
// is a mirror or glass one (the CPU reference's intersect).
std::vector<bool> specular_pixels(const Scene& scene) {
  const Camera& cam = scene.cameras[0];
  const CameraBasis basis = camera_basis(cam);
  std::vector<bool> mask(static_cast<std::size_t>(cam.width) * cam.height, false);
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      const Ray ray = camera_ray(cam, basis, x, cam.height - 1 - y);
      double best = ray.t_max;
      bool specular = false;
      for (const Occluder& o : scene.occluders) {
        const auto h = std::visit(
            [&](const auto& k) -> std::optional<OccluderHit> {
              using K = std::decay_t<decltype(k)>;
              if constexpr (K::kGpu == GpuForm::kPoints) {
                return std::nullopt;
              } else {
                return k.intersect(ray.origin, ray.dir, ray.t_min, best);
              }
            },
            o.shape);
        if (h && h->t < best) {
          best = h->t;
          specular = o.material.type != MaterialType::kDiffuse;
        }
      }
      mask[static_cast<std::size_t>(y) * cam.width + x] = specular;
    }
  }
  return mask;
}

// examples/cornell_caustic.json at size x size, its gi settings as shipped.
json cornell_caustic_as_shipped(int size) {
  std::ifstream in(std::string(BEAMCAST_SOURCE_DIR) + "/examples/cornell_caustic.json");
  json j = json::parse(in);
  j["cameras"][0]["width"] = size;
  j["cameras"][0]["height"] = size;
  return j;
}

json cornell_caustic(int size) {
  json j = cornell_caustic_as_shipped(size);
  j["gi"] = {{"photons", 20000}, {"caustic_photons", 20000}, {"direct", "photons"}};
  return j;
}

// The two tracers' frames of `j` over its mirror and glass pixels (at least
// `min_pixels` of them): relative L1 below 0.5%, fewer than 2% of the pixels
// off by more than 5%.
void expect_tracers_agree(const char* what, const json& j, std::size_t min_pixels) {
  const std::vector<bool> mask = specular_pixels(parse_scene(j, {}));
  const Difference d = compare(j, mask);
  std::printf("%s: %zu specular pixels, relative L1 %.2e, %.2f%% off by > 5%%\n", what, d.pixels,
              d.rel_l1, 100.0 * d.far_share);
  ASSERT_GT(d.pixels, min_pixels);
  EXPECT_LT(d.rel_l1, 5e-3);
  EXPECT_LT(d.far_share, 0.02);
}

// A mirror plane behind a diffuse box and sphere on a floor quad, lit by a
// spot and a point light (their photons) and seen in the mirror (analytic
// planes and spheres, triangles of two kinds under the BVH).
json mirror_room(int size) {
  return {
      {"background", {0.05, 0.07, 0.1}},
      {"occluders",
       {{{"type", "plane"}, {"point", {0, 0, -2}}, {"normal", {0, 0.2, 1}},
         {"material", {{"type", "mirror"}, {"reflectance", {0.9, 0.85, 0.8}}}}},
        {{"type", "quad"}, {"corner", {-4, -1, -3}}, {"edge_u", {0, 0, 8}}, {"edge_v", {8, 0, 0}},
         {"albedo", {0.7, 0.7, 0.7}}},
        {{"type", "box"}, {"center", {-1, -0.5, 0}}, {"size", {1, 1, 1}},
         {"albedo", {0.8, 0.3, 0.2}}},
        {{"type", "sphere"}, {"center", {1, -0.4, 0}}, {"radius", 0.6},
         {"albedo", {0.2, 0.5, 0.8}}}}},
      {"lights",
       {{{"type", "spot"}, {"position", {0, 3, 2}}, {"direction", {0, -1, -0.6}},
         {"inner_deg", 25}, {"outer_deg", 45}, {"power", 300}},
        {{"type", "point"}, {"position", {2, 2, 3}}, {"power", 80}}}},
      {"gi", {{"photons", 20000}, {"caustic_photons", 20000}, {"direct", "photons"}}},
      {"cameras",
       {{{"position", {0.5, 1.0, 4.0}}, {"target", {0, 0, -2}}, {"fov_y", 50}, {"width", size},
         {"height", size}}}}};
}

// By default ("auto") a frame uses the GPU tracer on a hardware GL and Embree
// on llvmpipe; "gpu" selects the GPU tracer, "cpu" Embree, and a scene it
// does not cover (a medium) falls back to the CPU. Direct light from shadow
// maps is covered.
TEST(SpecularGpu, TheSettingPicksTheTracer) {
  json j = cornell_caustic(16);
  static const std::unique_ptr<EglContext> context = EglContext::create();
  const EglContext::Current current(*context);
  PhotonCache cache;
  TableCache tables(4);
  const auto resources = [&](const json& s) {
    const Scene scene = parse_scene(s, {});
    const FramePlan plan = make_plan({scene});
    auto r = std::make_unique<SceneResources>(scene, tables, plan, &cache);
    return std::pair<bool, bool>{r->specular_gpu() != nullptr, r->gi_scene() != nullptr};
  };
  // "auto" (the default): the CPU on a software rasterizer, the GPU on a
  // hardware one.
  const std::string& gl_name = context->gl_renderer();
  const bool software = gl_name.find("llvmpipe") != std::string::npos ||
                        gl_name.find("softpipe") != std::string::npos;
  EXPECT_EQ(resources(j), std::make_pair(!software, software)) << gl_name;
  j["gi"]["specular_tracer"] = "gpu";
  EXPECT_EQ(resources(j), std::make_pair(true, false));
  j["gi"]["specular_tracer"] = "cpu";
  EXPECT_EQ(resources(j), std::make_pair(false, true));
  j["gi"]["specular_tracer"] = "gpu";
  j["medium"] = {{"sigma_a", 0.0001}, {"sigma_s", 0.0}};
  EXPECT_EQ(resources(j), std::make_pair(false, true));
  j.erase("medium");
  j["gi"]["direct"] = "shadow_maps";
  EXPECT_EQ(resources(j), std::make_pair(true, false));
}

// cornell_caustic at 48^2 (K = 2): the quad walls (one-sided triangles in
// the BVH), the quad light seen in the mirror and through the glass, the
// caustic photons gathered through the glass (direct light from photons).
TEST(SpecularGpu, CornellCausticMatchesTheCpuTracer) {
  expect_tracers_agree("cornell_caustic 48^2", cornell_caustic(48), 200);
}

// cornell_caustic as shipped (gi.direct "shadow_maps": the direct points'
// light with shadow rays where a ray lands; 100 000 global photons without
// those straight from the light; 2 x 2 rays a pixel) at 64^2. In groups of
// 8 x 8 llvmpipe ended the loops of a group once they had turned 65 535
// times together, and the last rays of 57 pixels were lost (0.74-0.75 of
// the CPU's value, 0.14 where the lost ray saw the light): the test fails
// that way with the groups of 8 x 8 on llvmpipe (shaders/specular_serial_on.glsl).
TEST(SpecularGpu, CornellCausticWithShadowMapsMatchesTheCpuTracer) {
  const json j = cornell_caustic_as_shipped(64);
  ASSERT_FALSE(j.contains("gi"));  // the defaults: "shadow_maps", 100 000 photons, K = 2
  expect_tracers_agree("cornell_caustic 64^2, shadow maps", j, 400);
}

TEST(SpecularGpu, MirrorRoomMatchesTheCpuTracer) {
  expect_tracers_agree("mirror room 48^2", mirror_room(48), 200);
}

}  // namespace
}  // namespace beamcast
