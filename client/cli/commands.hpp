// Subcommands of the `beamcast` tool; each registers itself on the CLI11 app.
#pragma once

#include <CLI/CLI.hpp>

namespace beamcast::cli {

void add_render_command(CLI::App& app);
void add_info_command(CLI::App& app);

}  // namespace beamcast::cli
