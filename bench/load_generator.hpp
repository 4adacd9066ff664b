// `beamcast load`'s settings and its run (bench/load_generator.cpp); the
// command's options that fill LoadArgs are in cli/load_command.cpp.
#pragma once

#include <string>

#include "protocol/data_dir.hpp"

namespace beamcast::bench {

struct LoadArgs {
  std::string server;
  int connections = 16;
  double duration_s = 10;
  long long requests = 0;  // total; 0: until duration
  double rate = 0;         // requests/s over all connections; 0: closed loop
  int size = 256;
  std::string scene_file = (find_data_dir("examples") / "paper_10sets.json").string();
  std::string poses = "mix";  // fixed, orbit, random, mix
  int cameras = 0;            // cameras per request; 0: mix of 1 and 4
  double verify_fraction = 0.02;
  int tolerance = 1;  // max |difference| per 8-bit channel against the local render
  int inflight_per_connection = 8;
  int pipeline = 1;  // closed loop: requests each connection keeps in flight
  // The mix: a preview-like class and a batch-like class (either may be 0).
  int preview_connections = 0;
  int preview_size = 256;
  double preview_budget_ms = 33;
  double preview_step_deg = 3;  // orbit step between a connection's frames
  int batch_connections = 0;
  int batch_cameras = 16;
  int batch_size = 256;
  double batch_rate = 0;  // requests/s over the batch connections; 0: closed loop
  int batch_pipeline = 1;
  // Retries (docs/deploy.md): a connection that drops or cannot be made is
  // opened again after a backoff with full jitter, and its unanswered
  // requests are sent again while the retry budget allows.
  int max_attempts = 5;  // consecutive tries of a connection; 1: no retries
  double busy_backoff_ms = 20;  // closed loop: pause after a "busy" answer, as a polite client does  // open loop: more than this is a client-side skip
  double timeout_s = 60;
  double timeline_ms = 1000;  // width of the report's timeline buckets
  std::string token;
  // "png" (not asked), "raw" or "raw_zstd": asked for in each connection's
  // hello (PROTOCOL.md, "Frame formats"); every frame is still decoded.
  std::string frame_format = "png";
  bool json_out = false;
  bool quiet = false;
};

// Runs the load against args.server and prints the report (text, or JSON with
// json_out). Returns 0, or 3 when a verified frame differed from the local
// render; throws std::invalid_argument for a bad HOST:PORT and
// std::runtime_error when the scene or the server cannot be used.
int run_load(const LoadArgs& args);

}  // namespace beamcast::bench
