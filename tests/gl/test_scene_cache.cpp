// The renderer's scene-content cache (render/scene_gpu_cache.hpp, issue 39):
// uploads of occluder triangles and SLIM sphere records are kept across
// renders by content. A hit must give the frame a renderer without the
// entry gives (compared bit for bit: the same vertex and sphere records
// reach the same shaders, so there is no tolerance to argue), and a change
// of content must miss.
#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <string>

#include "protocol/occluders/slim.hpp"
#include "protocol/scene_json.hpp"
#include "render/renderer.hpp"
#include "slim/test_shapes.hpp"

namespace beamcast {
namespace {

const std::string kExamples = std::string(BEAMCAST_SOURCE_DIR) + "/examples";

// examples/mesh_occluder.json (the torus OBJ beside a beam) at 64 x 64, the
// mesh moved by `dx`, with a SLIM sphere added.
Scene mesh_and_slim_scene(double dx) {
  std::ifstream in(kExamples + "/mesh_occluder.json");
  nlohmann::json j = nlohmann::json::parse(in);
  j["occluders"][0]["translate"][0] = dx;
  for (auto& cam : j["cameras"]) {
    cam["width"] = 64;
    cam["height"] = 64;
  }
  SceneLoadOptions opts;
  opts.assets_dir = kExamples;
  Scene scene = parse_scene(j, opts);
  scene.occluders.push_back(Occluder{
      SlimOccluder::from_spheres(test::slim_sphere({1.4, 0.0, 0.0}, 0.5, 200)), {0.8, 0.6, 0.4}, {}});
  return scene;
}

TEST(SceneCache, HitsGiveTheFramesOfARendererWithoutTheEntry) {
  Renderer warm;
  const Scene a = mesh_and_slim_scene(0.0);
  const auto first = warm.render(a);
  const SceneGpuCache::Stats after_first = warm.scene_cache_stats();
  EXPECT_EQ(after_first.misses, 2u);  // the triangles and the SLIM records
  EXPECT_EQ(after_first.entries, 2u);
  EXPECT_GT(after_first.bytes, 0u);

  // A second parse of the same content (another Scene, another mesh in
  // memory, the same SLIM surface): hits, and the same frames.
  const Scene a2 = mesh_and_slim_scene(0.0);
  const auto again = warm.render(a2);
  const SceneGpuCache::Stats after_again = warm.scene_cache_stats();
  EXPECT_EQ(after_again.hits, after_first.hits + 2);  // the triangles and the SLIM records
  ASSERT_EQ(again.size(), first.size());
  for (std::size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(again[i].image.rgb, first[i].image.rgb) << "camera " << i;
  }

  // Moved content misses, and its frame is what a fresh renderer draws.
  const Scene b = mesh_and_slim_scene(0.3);
  const auto moved = warm.render(b);
  EXPECT_EQ(warm.scene_cache_stats().misses, after_again.misses + 1);
  Renderer fresh;
  const auto moved_fresh = fresh.render(b);
  ASSERT_EQ(moved.size(), first.size());
  for (std::size_t i = 0; i < first.size(); ++i) {
    EXPECT_NE(moved[i].image.rgb, first[i].image.rgb) << "camera " << i;
    EXPECT_EQ(moved[i].image.rgb, moved_fresh[i].image.rgb) << "camera " << i;
  }
}

TEST(SceneCache, EvictsTheLeastRecentlyUsedWithinItsBudget) {
  SceneGpuCache cache(100);
  cache.put("a", std::make_shared<int>(1), 40);
  cache.put("b", std::make_shared<int>(2), 40);
  ASSERT_NE(cache.find<int>("a"), nullptr);  // "a" is now the most recently used
  cache.put("c", std::make_shared<int>(3), 40);
  EXPECT_EQ(cache.find<int>("b"), nullptr);
  EXPECT_EQ(*cache.find<int>("a"), 1);
  EXPECT_EQ(*cache.find<int>("c"), 3);
  EXPECT_EQ(cache.stats().bytes, 80u);
  EXPECT_EQ(cache.stats().evictions, 1u);
  cache.put("huge", std::make_shared<int>(4), 101);  // over the whole budget: not kept
  EXPECT_EQ(cache.find<int>("huge"), nullptr);
  cache.shrink_to(0);
  EXPECT_EQ(cache.stats().entries, 0u);
}

}  // namespace
}  // namespace beamcast
