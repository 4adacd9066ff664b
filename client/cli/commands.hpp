// Subcommands of the `beamcast` tool; each registers itself on the CLI11 app.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace beamcast::cli {

void add_render_command(CLI::App& app);
void add_info_command(CLI::App& app);
// `ping` and `stats`, which talk to beamcast-server.
void add_server_commands(CLI::App& app);
// `bench accuracy`: integration settings against the CPU reference (bench/).
void add_bench_command(CLI::App& app);
// `load`: a load generator against beamcast-server (load_command.cpp).
void add_load_command(CLI::App& app);

// `beamcast render --server HOST:PORT`: the render happens on the server.
struct RemoteRenderArgs {
  std::string server;    // HOST:PORT
  std::string scene;     // scene file sent inline; or
  std::string scene_id;  // a scene stored on the server
  std::string out = ".";
  std::string encoding = "binary";
  double timeout_s = 120;
  bool json = false;
};
int run_remote_render(const RemoteRenderArgs& args);

}  // namespace beamcast::cli
