// `beamcast bench accuracy`: error against the double-precision CPU reference
// versus GPU time, for every integration setting (RenderSettings) on a fixed
// set of scenes. Writes accuracy.csv, accuracy.md and, through
// bench/plot_accuracy.py, accuracy.png and accuracy_tables.png.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/bench_scenes.hpp"
#include "protocol/scene.hpp"
#include "render/egl_context.hpp"

namespace beamcast::bench {

struct AccuracyOptions {
  std::filesystem::path out;
  bool quick = false;  // 3 scenes, a coarse grid, 3 repeats: under a minute on 2 cores
  int size = 0;        // frame width and height; 0: 512, or 128 with `quick`
  std::vector<std::string> scenes;  // only these scenes; empty: the whole set
  EglOptions egl;
  bool plots = true;  // run bench/plot_accuracy.py after the CSV
};

// One measured (scene, setting) pair: one CSV row.
struct AccuracyRow {
  std::string scene;
  RenderSettings settings;
  double gpu_ms = 0.0;       // median over the repeats, whole frame (GL timestamps)
  double beam_gpu_ms = 0.0;  // median, the "beams" pass alone
  double wall_ms = 0.0;      // median, render call for the camera incl. read-back
  int repeats = 0;
  double max_abs = 0.0;  // HDR error against the reference, all channels
  double rms = 0.0;
  double rel_l1 = 0.0;
  double psnr_db = 0.0;  // 8-bit tone-mapped frame against the tone-mapped reference
  std::int64_t nonfinite = 0;
};

// Names as the scene JSON spells them ("table", "chord_warped", "simpson").
const char* method_name(IntegrationMethod m);
const char* layout_name(TableLayout l);
const char* filter_name(TableFilter f);
const char* rule_name(MarchRule r);
// A short label of the setting for people: "table chord_warped/shader 64",
// "march simpson 16", "closed_form".
std::string setting_label(const RenderSettings& s);

// The settings measured on `scene`, in CSV order. `skipped` receives a line
// for each group of settings left out on purpose (march caps).
std::vector<RenderSettings> settings_grid(const BenchScene& scene, bool quick,
                                          std::vector<std::string>* skipped);

// Runs the benchmark; progress on stderr. Returns the process exit code.
int run_accuracy(const AccuracyOptions& opts);

}  // namespace beamcast::bench
