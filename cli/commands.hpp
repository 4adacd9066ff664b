// Subcommands of the `beamcast` tool; each registers itself on the CLI11 app.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "cli/frame_choice.hpp"

namespace beamcast::cli {

void add_render_command(CLI::App& app);
void add_info_command(CLI::App& app);
// `ping` and `stats`, which talk to beamcast-server.
void add_server_commands(CLI::App& app);
// `bench accuracy`: integration settings against the CPU reference (bench/).
void add_bench_command(CLI::App& app);
// `load`: a load generator against beamcast-server (bench/load_generator.hpp).
void add_load_command(CLI::App& app);
// `slim fit`: a SLIM surface fitted to a triangle mesh (slim/).
void add_slim_command(CLI::App& app);

// `beamcast render --server HOST:PORT`: the render happens on the server.
struct RemoteRenderArgs {
  std::string server;    // HOST:PORT
  std::string scene;     // scene file sent inline; or
  std::string scene_id;  // a scene stored on the server
  std::string out = ".";
  std::string encoding = "binary";
  std::string token;  // presented in hello when set
  // "png" (not asked), "raw" or "raw_zstd": frames come as samples and are
  // written as PNG here (PROTOCOL.md, "Frame formats").
  std::string frame_format = "png";
  double timeout_s = 120;
  bool json = false;
  FrameChoice choice;  // --camera, --size
  std::string prefix;  // before each file name
};
int run_remote_render(const RemoteRenderArgs& args);

// `beamcast render --rig SPEC` or `--path FILE`: numbered PNGs (frame_0000.png
// ...) of a rig or a keyframed camera path, locally or with --server.
struct SequenceArgs {
  std::string scene;
  std::string out = ".";
  std::string assets;
  std::string rig;   // orbit:K, cubemap[:SIZE], stereo[:SEPARATION]
  std::string path;  // camera path JSON (protocol/camera_path.hpp)
  int frames = 0;    // path frames (0: the file's, else one per keyframe)
  int batch = 12;    // views per render call (local) or request (server)
  bool json = false;
  int device = -1;
  std::string platform = "auto";
  std::string scene_id;    // with server: a stored scene instead of the file (scene.get)
  std::string prefix;      // file names: PREFIX + frame_0000.png ...
  std::string server;      // HOST:PORT, or several separated by commas
  int connections = 2;     // workers per server (each its own connection)
  std::string token;       // presented in hello when set
  std::string encoding = "binary";
  double timeout_s = 120;
  FrameChoice choice;  // --camera (the one that frames the rig or path), --size
};
int run_sequence(const SequenceArgs& args);

}  // namespace beamcast::cli
