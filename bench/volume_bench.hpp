// `beamcast bench volumes` (issue 17, item 5): the seed's tables 2-4 on this
// machine — frame time against S_z (samples per voxel), S_xy (render scale,
// upscaled) and R_v (pyramid level and rule) — each with the error column
// the seed never had (the frame against the CPU reference's), plus the
// opacity correction at coarse steps, and early ray termination and
// empty-space skipping on a sparse volume (the skull) against a dense one.
// Writes volumes.csv and volumes.md.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "render/egl_context.hpp"

namespace beamcast::bench {

struct VolumeBenchOptions {
  std::filesystem::path out;
  bool quick = false;  // 96x96, small volumes, fewer settings (the test's run)
  int size = 0;        // 0: 512 (quick: 96)
  int repeats = 3;     // GPU frames per row (the median is reported)
  // The reference's march: samples per voxel spacing (each step's middle).
  double reference_spv = 8.0;
  // The skull (INRIA .inr, e.g. from scripts/fetch_cgal_volumes.sh): the
  // sparse volume of the ERT and skipping rows; without it a sparse
  // Marschner-Lobb transfer function stands in.
  std::filesystem::path skull;
  bool images = false;  // each row's frame as a PNG beside the tables
  EglOptions egl;
};

// Runs the benchmark; throws on failure.
void run_volume_bench(const VolumeBenchOptions& opts);

}  // namespace beamcast::bench
