// What every `beamcast` command that talks to a server shares: the --server
// address (default $BEAMCAST_SERVER, else 127.0.0.1:7878), the --token
// (default $BEAMCAST_TOKEN) and a connection that presents it.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "client/client.hpp"

namespace beamcast::cli {

// $BEAMCAST_SERVER if set and not empty, else 127.0.0.1:7878.
std::string default_server();

// --server HOST:PORT, defaulting to default_server().
CLI::Option* add_server_option(CLI::App* cmd, std::string* server);
// --token, defaulting to $BEAMCAST_TOKEN.
CLI::Option* add_token_option(CLI::App* cmd, std::string* token);

// Connects (bad HOST:PORT text is a usage error) and, with a token, says
// hello with it; a refused hello throws std::runtime_error with the server's words.
void connect_to_server(client::Client& c, const std::string& server, const std::string& token,
                       double timeout_s);
void connect_to_server(client::Client& c, const client::Endpoint& ep, const std::string& token,
                       double timeout_s);

}  // namespace beamcast::cli
