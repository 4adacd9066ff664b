// Outputs of the accuracy benchmark: the CSV (for scripts), the Markdown
// summary (for people) and the plots (bench/plot_accuracy.py).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "bench/accuracy.hpp"

namespace beamcast::bench {

// What the summary says about the run besides the rows.
struct RunInfo {
  std::string renderer;  // the GL device string
  std::string machine;   // CPU count, OS
  int size = 0;
  bool quick = false;
  struct Reference {
    std::string scene;
    int beams = 0;
    double seconds = 0.0;
  };
  std::vector<Reference> references;
  std::vector<std::string> skipped;  // settings left out on purpose
  double total_s = 0.0;
  // The paper's 32x32 uniform table against the default, rendered alternately
  // (A B A B ...) so that both see the same machine load: medians in ms.
  struct Interleaved {
    std::string scene;
    double paper_gpu_ms = 0.0, default_gpu_ms = 0.0;
    double paper_beam_ms = 0.0, default_beam_ms = 0.0;
    double paper_rel_l1 = 0.0, default_rel_l1 = 0.0;
    int frames = 0;  // per side
  };
  std::vector<Interleaved> interleaved;
};

// The exact CSV header, without a newline.
const char* csv_header();
void write_csv(const std::filesystem::path& file, const std::vector<AccuracyRow>& rows);
void write_summary(const std::filesystem::path& file, const std::vector<AccuracyRow>& rows,
                   const std::vector<BenchScene>& scenes, const RunInfo& info);
// Runs bench/plot_accuracy.py CSV OUT_DIR with python_interpreter(). Returns an empty
// string on success, else one line saying why there are no plots.
std::string run_plot_script(const std::filesystem::path& csv, const std::filesystem::path& out_dir);
// `s` as one POSIX shell word (single quotes).
std::string shell_quote(const std::string& s);
// The Python that runs the bench scripts and plots: $BEAMCAST_PYTHON where
// set (a machine whose numpy and matplotlib live in another interpreter, e.g.
// a virtual environment), else /usr/bin/python3 (Debian's, as README installs).
std::string python_interpreter();

}  // namespace beamcast::bench
