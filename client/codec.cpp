// Pure helpers of the client: HOST:PORT parsing.
#include <stdexcept>

#include "client/client.hpp"

namespace beamcast::client {

Endpoint parse_endpoint(std::string_view text) {
  const std::string quoted = "\"" + std::string(text) + "\"";
  Endpoint ep;
  std::string_view port;
  if (!text.empty() && text.front() == '[') {
    // "[::1]:7878": an IPv6 literal has colons of its own, so it is bracketed.
    const std::size_t close = text.find(']');
    if (close == std::string_view::npos) throw std::invalid_argument(quoted + ": missing ']'");
    if (close + 1 >= text.size() || text[close + 1] != ':') {
      throw std::invalid_argument(quoted + ": expected ':PORT' after ']'");
    }
    ep.host = std::string(text.substr(1, close - 1));
    port = text.substr(close + 2);
  } else {
    const std::size_t colon = text.rfind(':');
    if (colon == std::string_view::npos) {
      throw std::invalid_argument(quoted + " is not HOST:PORT (no ':PORT')");
    }
    ep.host = std::string(text.substr(0, colon));
    if (ep.host.find(':') != std::string::npos) {
      throw std::invalid_argument(quoted + ": write an IPv6 address in brackets, [ADDR]:PORT");
    }
    port = text.substr(colon + 1);
  }
  if (ep.host.empty()) throw std::invalid_argument(quoted + ": the host is empty");
  // Digits only (no sign, no spaces), at most 5 of them so the sum cannot overflow.
  bool digits = !port.empty() && port.size() <= 5;
  unsigned value = 0;
  for (char c : port) {
    if (c < '0' || c > '9') digits = false;
    value = value * 10 + static_cast<unsigned>(c - '0');
  }
  if (!digits || value == 0 || value > 65535) {
    throw std::invalid_argument(quoted + ": port \"" + std::string(port) +
                                "\" is not a number in 1..65535");
  }
  ep.port = static_cast<std::uint16_t>(value);
  return ep;
}

}  // namespace beamcast::client
