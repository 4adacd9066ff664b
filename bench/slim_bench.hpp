// `beamcast bench slim` (issue 16, item 5): SLIM point sampling against the
// CPU reference per knob — sampling S, depth threshold t, the second stage
// on and off — for each model and zoom (0.25x to 16x of the size that fills
// the frame): sample slots per frame, GPU time, hole and spurious pixels,
// depth and normal error. Writes slim.csv and slim.md.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "render/egl_context.hpp"

namespace beamcast::bench {

struct SlimBenchOptions {
  std::filesystem::path out;
  bool quick = false;  // 128x128, the generated shapes, fewer settings
  int size = 0;        // 0: 512 (quick: 128)
  int repeats = 3;     // GPU frames per row (the median is reported)
  // Coverage pictures of the zoom rows (MODEL_zoomZ_fill|nofill.png): grey
  // covered by both, red holes, blue spurious pixels.
  bool images = false;
  // The reference's depth and normal averaged over K x K rays per pixel (1:
  // the centre ray; coverage always from the centre ray).
  int reference_samples = 1;
  std::vector<double> zooms;  // empty: 0.25, 1, 4, 16 (quick: 0.25, 1, 4)
  bool zoom_only = false;     // skip the S and t rows
  bool no_generated = false;  // skip the generated sphere and torus
  // Only the rows of these evaluations ("field", "patch", "blend"); empty: all.
  std::vector<std::string> evaluations;
  // SLIM model files (JSON or binary, e.g. from `beamcast slim fit`) besides
  // the generated sphere and torus.
  std::vector<std::filesystem::path> models;
  // The meshes the models were fitted to, in the same order (optional): the
  // everyday alternative, each rasterized by the same renderer as a mesh
  // occluder at the same cameras: its GPU time and its image's difference
  // from the SLIM frame (slim_mesh.md).
  std::vector<std::filesystem::path> meshes;
  EglOptions egl;
};

int run_slim_bench(const SlimBenchOptions& opts);

}  // namespace beamcast::bench
