// The scenes of the accuracy benchmark, built in code so a run is reproducible
// without any file but the paper examples. Every scene has a black background,
// no occluders and exactly one camera of the requested size.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "protocol/scene.hpp"

namespace beamcast::bench {

struct BenchScene {
  std::string name;
  Scene scene;  // scene.cameras holds the one camera to render
  // A density scene (density_*): its table-size curve is plotted and it gets
  // the "cheapest setting reaching rel_l1 <= 1e-3" line of the summary.
  bool density_study = false;
  // Whether every beam's density has an exact antiderivative in the shader
  // (the closed_form method is refused otherwise).
  bool closed_form = false;
  // March sample counts above this are skipped (their frame time would blow
  // the run's budget on a software rasterizer); 0: no cap.
  int max_march_samples = 0;
  // Table sizes 8, 32, 128, 1024 only (every factor of 4, and the largest)
  // instead of every power of two: for scenes whose frames take ~0.6 s here.
  bool coarse_tables = false;
};

// The full set: paper_1set, paper_5sets, paper_10sets, thin_shell,
// grazing_capsule, beams_100, beams_1000, density_{abe,shell,linear,quadratic,gaussian}.
// `examples_dir` holds the paper_*.json and thin_shell.json files.
std::vector<BenchScene> full_scene_set(const std::filesystem::path& examples_dir, int size);

// The --quick set: paper_1set, thin_shell, grazing_capsule.
std::vector<BenchScene> quick_scene_set(const std::filesystem::path& examples_dir, int size);

}  // namespace beamcast::bench
