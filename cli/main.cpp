// beamcast: command-line tool of the Beamcast render service.
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "cli/commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"beamcast: render energy-beam scenes headless (offline or through a server)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "beamcast " BEAMCAST_VERSION);
  beamcast::cli::add_render_command(app);
  beamcast::cli::add_info_command(app);
  beamcast::cli::add_server_commands(app);
  beamcast::cli::add_bench_command(app);
  beamcast::cli::add_load_command(app);
  beamcast::cli::add_slim_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "beamcast: %s\n", e.what());
    return 1;
  }
  return 0;
}
