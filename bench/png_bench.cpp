// PNG encoding cost against size, to choose the server's zlib level and filter
// (docs/performance.md). The frames are the CPU reference renders of the demo
// scene and of the occluder example, so the numbers do not depend on a GPU.
#include <benchmark/benchmark.h>
#include <png.h>

#include <filesystem>

#include "protocol/data_dir.hpp"
#include "protocol/scene_json.hpp"
#include "render/image.hpp"
#include "render/reference.hpp"

namespace {

using namespace beamcast;

const Image& frame(int which) {
  static Image frames[2];
  if (frames[which].rgb.empty()) {
    const char* names[2] = {"paper_10sets", "beam_occluder"};
    const auto dir = find_data_dir("examples");
    SceneLoadOptions opts;
    opts.assets_dir = dir;
    const Scene scene = load_scene_file(dir / (std::string(names[which]) + ".json"), opts);
    frames[which] = tone_map(render_reference(scene, scene.cameras[0]), scene.output);
  }
  return frames[which];
}

void BM_EncodePng(benchmark::State& state) {
  const Image& img = frame(static_cast<int>(state.range(0)));
  const int level = static_cast<int>(state.range(1));
  const int filters = static_cast<int>(state.range(2));
  std::size_t bytes = 0;
  for ([[maybe_unused]] auto _ : state) {  // the analyzer sees a dead store
    auto png = encode_png(img, level, filters);
    bytes = png.size();
    benchmark::DoNotOptimize(png.data());
  }
  state.counters["bytes"] = static_cast<double>(bytes);
  state.counters["ratio"] = static_cast<double>(bytes) / (img.width * img.height * 3.0);
  state.SetLabel(std::string(state.range(0) ? "beam_occluder" : "paper_10sets") +
                 (filters == PNG_FILTER_NONE ? " filter=none"
                  : filters == PNG_FILTER_SUB ? " filter=sub"
                  : filters == PNG_FILTER_UP  ? " filter=up"
                                              : " filter=all(adaptive)"));
}

void Args(benchmark::internal::Benchmark* b) {
  for (int scene : {0, 1}) {
    for (int level : {0, 1, 2, 3, 6, 9}) {
      for (int filters : {PNG_FILTER_NONE, PNG_FILTER_SUB, PNG_FILTER_UP, PNG_ALL_FILTERS}) {
        b->Args({scene, level, filters});
      }
    }
  }
}

BENCHMARK(BM_EncodePng)->Apply(Args)->Unit(benchmark::kMillisecond)->ArgNames({"scene", "level", "filters"});

}  // namespace

BENCHMARK_MAIN();
