#include "server/auth.hpp"

#include <boost/asio/ip/address.hpp>

#include <stdexcept>

#include "protocol/errors.hpp"

namespace beamcast {

bool is_loopback_address(const std::string& address) {
  boost::system::error_code ec;
  const auto a = boost::asio::ip::make_address(address, ec);
  if (ec) throw std::invalid_argument("bind address \"" + address + "\" is not an IP address");
  if (a.is_v6() && a.to_v6().is_v4_mapped()) {
    return boost::asio::ip::make_address_v4(boost::asio::ip::v4_mapped, a.to_v6()).is_loopback();
  }
  return a.is_loopback();
}

void check_bind_policy(const ServerConfig& c) {
  if (is_loopback_address(c.bind) || token_required(c) || c.insecure_no_token) return;
  throw std::invalid_argument(
      "binding " + c.bind +
      " (not a loopback address) needs a shared token: pass --token or set BEAMCAST_TOKEN, "
      "or --insecure-no-token to accept anyone who can reach the port (docs/security.md)");
}

bool token_matches(std::string_view presented, std::string_view expected) {
  // Walk the expected token in full whatever the presented one holds; fold a
  // length mismatch into the same accumulator. No early exit, no branch on data.
  unsigned diff = static_cast<unsigned>(presented.size() ^ expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const unsigned char p =
        presented.empty() ? 0 : static_cast<unsigned char>(presented[i % presented.size()]);
    diff |= p ^ static_cast<unsigned char>(expected[i]);
  }
  // An empty configured token never matches (auth is off then; callers check).
  return diff == 0 && !expected.empty();
}

bool http_request_authorized(const ServerConfig& config, std::string_view path,
                             std::string_view authorization_header) {
  if (!token_required(config)) return true;
  if (!path.starts_with("/api/") && path != "/metrics" && path != "/v1/render") return true;
  constexpr std::string_view kBearer = "Bearer ";
  if (!authorization_header.starts_with(kBearer)) return false;
  return token_matches(authorization_header.substr(kBearer.size()), config.token);
}

void check_request_token(const ServerConfig& config, bool presents_token,
                         const nlohmann::json& params, bool authenticated) {
  if (!token_required(config)) return;
  if (!presents_token) {
    if (authenticated) return;
    throw ProtocolError({"unauthorized",
                         "this server requires a token: send hello with params.token first", ""});
  }
  const auto it = params.find("token");
  if (it == params.end()) {
    throw ProtocolError(
        {"unauthorized", "this server requires a token: params.token is missing", "/params/token"});
  }
  if (!it->is_string()) {
    throw ProtocolError({"unauthorized", "params.token must be a string", "/params/token"});
  }
  if (!token_matches(it->get_ref<const std::string&>(), config.token)) {
    throw ProtocolError({"unauthorized", "the token does not match", "/params/token"});
  }
}

}  // namespace beamcast
