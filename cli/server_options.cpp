#include "cli/server_options.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <stdexcept>

namespace beamcast::cli {

std::string default_server() {
  const char* env = std::getenv("BEAMCAST_SERVER");
  return env && *env ? std::string(env) : std::string("127.0.0.1:7878");
}

CLI::Option* add_server_option(CLI::App* cmd, std::string* server) {
  *server = default_server();
  return cmd->add_option("--server", *server,
                         "Server address HOST:PORT (default: $BEAMCAST_SERVER, else "
                         "127.0.0.1:7878)")
      ->capture_default_str();
}

CLI::Option* add_token_option(CLI::App* cmd, std::string* token) {
  return cmd->add_option("--token", *token,
                         "Token for hello, for servers started with one (default: "
                         "$BEAMCAST_TOKEN)")
      ->envname("BEAMCAST_TOKEN");
}

void connect_to_server(client::Client& c, const std::string& server, const std::string& token,
                       double timeout_s) {
  client::Endpoint ep;
  try {
    ep = client::parse_endpoint(server);
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("--server", e.what());
  }
  connect_to_server(c, ep, token, timeout_s);
}

void connect_to_server(client::Client& c, const client::Endpoint& ep, const std::string& token,
                       double timeout_s) {
  const auto timeout = std::chrono::milliseconds(static_cast<long long>(timeout_s * 1000));
  c.set_receive_timeout(timeout);
  c.connect(ep.host, ep.port, std::min(timeout, std::chrono::milliseconds(10000)));
  if (token.empty()) return;
  const client::Response r = c.call("hello", {{"protocol", 1}, {"token", token}});
  if (!r.ok) {
    throw std::runtime_error("hello refused: [" + r.error.code + "] " + r.error.message);
  }
}

}  // namespace beamcast::cli
