// `beamcast bench views`: K views of the paper's 10-set scene rendered as one
// K-camera request versus K single-camera requests pipelined on one
// connection, end to end through a beamcast-server (started as a child
// process, or given with --server), plus the renderer alone with multi-view
// batching on and off. Writes views.csv, views.md and (bench/plot_views.py)
// views.png. Variants are interleaved per round so they share the machine's load.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "render/egl_context.hpp"

namespace beamcast::bench {

struct ViewsOptions {
  std::filesystem::path out;
  bool quick = false;        // K = 1, 2, 4 at 128x128, 1 round: seconds
  std::vector<int> views;    // empty: 1, 2, 4, 8, 16, 36 (quick: 1, 2, 4)
  int size = 0;              // 0: 512 (quick: 128)
  int rounds = 0;            // 0: 3 (quick: 1)
  std::string server;        // HOST:PORT of a running server; empty: start one
  std::filesystem::path server_binary;  // empty: beamcast-server beside this program
  bool renderer = true;      // also time the renderer in-process, batched vs single
  bool plots = true;
  EglOptions egl;
};

int run_views(const ViewsOptions& opts);

}  // namespace beamcast::bench
