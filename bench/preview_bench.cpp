// Measurements behind docs/performance.md, "Interactive preview":
//  1. PNG (the server's setting) against JPEG encoding of real frames at 256²
//     and 512²: time and size, interleaved in rounds so both see the same load;
//  2. every accuracy-controller level on the 10-set scene at 512²: render and
//     encode time, the frame rate they allow, and the image error against the
//     full-accuracy frame (before and after JPEG).
// Not a test: prints markdown tables. Usage: beamcast_bench_preview [rounds]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "protocol/data_dir.hpp"
#include "protocol/scene_json.hpp"
#include "render/accuracy_controller.hpp"
#include "render/image.hpp"
#include "render/jpeg.hpp"
#include "render/renderer.hpp"

namespace {

using namespace beamcast;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// The server's PNG setting (server/config.hpp): zlib level 2, SUB filter.
constexpr int kPngLevel = 2;
constexpr int kPngSub = 0x10;

Scene demo_scene(const std::string& name) {
  const auto dir = find_data_dir("examples");
  SceneLoadOptions opts;
  opts.assets_dir = dir;
  return load_scene_file(dir / (name + ".json"), opts);
}

void encode_table(Renderer& renderer, const Scene& scene, int rounds) {
  std::printf("\n### PNG vs JPEG encoding (10-set scene, full-accuracy frames; median of %d interleaved rounds)\n\n",
              rounds);
  std::printf("| size | format | encode ms | bytes | encode time vs PNG | size vs PNG |\n|---|---|---|---|---|---|\n");
  for (int size : {256, 512}) {
    Camera cam = scene.cameras[0];
    cam.width = cam.height = size;
    const Image img = renderer.render(scene, {cam})[0].image;
    const int qualities[] = {75, 80, 85, 90, 92};
    std::vector<double> png_ms;
    std::vector<std::vector<double>> jpeg_ms(std::size(qualities));
    std::size_t png_bytes = 0;
    std::vector<std::size_t> jpeg_bytes(std::size(qualities));
    for (int r = 0; r < rounds; ++r) {
      auto t = Clock::now();
      png_bytes = encode_png(img, kPngLevel, kPngSub).size();
      png_ms.push_back(ms_since(t));
      for (std::size_t q = 0; q < std::size(qualities); ++q) {
        t = Clock::now();
        jpeg_bytes[q] = encode_jpeg(img, qualities[q]).size();
        jpeg_ms[q].push_back(ms_since(t));
      }
    }
    const double p = median(png_ms);
    std::printf("| %d² | PNG (level 2, sub) | %.2f | %zu | 1 | 1 |\n", size, p, png_bytes);
    for (std::size_t q = 0; q < std::size(qualities); ++q) {
      const double j = median(jpeg_ms[q]);
      std::printf("| %d² | JPEG q%d | %.2f | %zu | %.3f | %.3f |\n", size, qualities[q], j,
                  jpeg_bytes[q], j / p, static_cast<double>(jpeg_bytes[q]) / png_bytes);
    }
  }
}

void level_table(Renderer& renderer, const Scene& scene, const std::string& name, int rounds,
                 bool lod) {
  Camera cam = scene.cameras[0];
  cam.width = cam.height = 512;
  const auto ladder =
      lod ? preview_ladder(scene) : make_accuracy_ladder(scene.render, scene.has_gi());
  const Image full = renderer.render(scene, {cam})[0].image;
  struct Row {
    std::vector<double> render_ms, encode_ms, readback_ms;
    std::map<std::string, std::vector<double>> pass_ms;
    std::size_t bytes = 0;
    LevelError raw, jpeg;
  };
  std::vector<Row> rows(ladder.size());
  for (int r = 0; r < rounds + 1; ++r) {
    for (std::size_t l = 0; l < ladder.size(); ++l) {
      Scene s = scene;
      apply_accuracy_level(ladder[l], &s);
      FrameOptions fo;
      fo.resolution_scale = ladder[l].scale;
      auto t = Clock::now();
      FrameResult fr = std::move(renderer.render(s, {cam}, fo)[0]);
      const double render_ms = ms_since(t);
      const Image& img = fr.image;
      t = Clock::now();
      // Level 0 while moving is JPEG like every interactive frame; the still
      // frame (PNG) is the reference itself.
      const auto bytes = encode_jpeg(img, ladder[l].jpeg_quality);
      const double encode_ms = ms_since(t);
      if (r == 0) {  // warm-up round: tables built, shaders compiled
        rows[l].raw = compare_levels(img, full);
        rows[l].jpeg = compare_levels(decode_jpeg(bytes), full);
        rows[l].bytes = bytes.size();
        continue;
      }
      rows[l].render_ms.push_back(render_ms);
      rows[l].readback_ms.push_back(fr.readback_ms);
      for (const PassTiming& p : fr.passes) rows[l].pass_ms[p.name].push_back(p.gpu_ms);
      rows[l].encode_ms.push_back(encode_ms);
    }
  }
  std::vector<double> still_png;
  for (int r = 0; r < rounds; ++r) {
    const auto t = Clock::now();
    encode_png(full, kPngLevel, kPngSub);
    still_png.push_back(ms_since(t));
  }
  std::printf("\n### Controller levels (%s, 512², median of %d interleaved rounds)\n\n", name.c_str(), rounds);
  std::printf("| level | label | render ms | JPEG ms | frame ms | frames/s (serial) | RMS error (levels) | max error | PSNR dB | RMS after JPEG | PSNR after JPEG | JPEG bytes |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (std::size_t l = 0; l < ladder.size(); ++l) {
    const Row& row = rows[l];
    const double rm = median(row.render_ms), em = median(row.encode_ms);
    std::printf("| %zu | %s | %.1f | %.1f | %.1f | %.1f | %.3f | %d | %.1f | %.3f | %.1f | %zu |\n", l,
                ladder[l].label.c_str(), rm, em, rm + em, 1000.0 / (rm + em), row.raw.rms,
                row.raw.max_abs, row.raw.psnr_db, row.jpeg.rms, row.jpeg.psnr_db, row.bytes);
  }
  std::printf("\nStill frame (level 0, PNG level 2 sub): encode %.1f ms.\n", median(still_png));
  std::printf("\nWhere a frame's render time goes (median ms; GPU timestamps, read-back wall):\n\n");
  std::printf("| level | label | passes | read-back |\n|---|---|---|---|\n");
  for (std::size_t l = 0; l < ladder.size(); ++l) {
    std::string passes;
    for (const auto& [name, v] : rows[l].pass_ms) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%s%s %.2f", passes.empty() ? "" : ", ", name.c_str(), median(v));
      passes += buf;
    }
    std::printf("| %zu | %s | %s | %.2f |\n", l, ladder[l].label.c_str(), passes.c_str(),
                median(rows[l].readback_ms));
  }
}

}  // namespace

// beamcast_bench_preview [ROUNDS [EXAMPLE [nolod]]]: the encoding table and
// the controller levels of the 10-set scene, or only the levels of EXAMPLE
// (e.g. cornell_box: a lit scene's ladder splats a quarter of the photons
// and thins them by the preview's LOD; "nolod": the ladder without LOD).
int main(int argc, char** argv) {
  const int rounds = argc > 1 ? std::max(1, std::atoi(argv[1])) : 15;
  const std::string name = argc > 2 ? argv[2] : "paper_10sets";
  Renderer renderer;
  std::printf("renderer: %s\n", renderer.description().c_str());
  const Scene scene = demo_scene(name);
  if (name == "paper_10sets") encode_table(renderer, scene, rounds);
  level_table(renderer, scene, name, rounds, !(argc > 3 && std::string(argv[3]) == "nolod"));
  return 0;
}
