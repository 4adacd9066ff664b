// Pure helpers of the client: HOST:PORT parsing and base64 (nlohmann::json has
// no base64, and render responses with "encoding": "base64" carry PNGs in it).
#include <array>
#include <stdexcept>

#include "client/client.hpp"

namespace beamcast::client {
namespace {

constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

// 0..63 for alphabet characters, -1 for everything else (including '=').
constexpr std::array<int, 256> make_decode_table() {
  std::array<int, 256> t{};
  for (int& v : t) v = -1;
  for (int i = 0; i < 64; ++i) t[static_cast<unsigned char>(kAlphabet[i])] = i;
  return t;
}
constexpr std::array<int, 256> kDecode = make_decode_table();

}  // namespace

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

std::string base64_encode(std::span<const std::uint8_t> bytes) {
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const std::uint32_t v =
        (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  const std::size_t rest = bytes.size() - i;
  if (rest > 0) {
    std::uint32_t v = std::uint32_t{bytes[i]} << 16;
    if (rest == 2) v |= std::uint32_t{bytes[i + 1]} << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += rest == 2 ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::vector<std::uint8_t> base64_decode(std::string_view text) {
  if (text.size() % 4 != 0) {
    throw std::invalid_argument("base64: length " + std::to_string(text.size()) +
                                " is not a multiple of 4");
  }
  // Padding is one or two '=' at the very end; anywhere else is an error.
  std::size_t pad = 0;
  if (!text.empty() && text.back() == '=') pad = text[text.size() - 2] == '=' ? 2 : 1;
  std::vector<std::uint8_t> out;
  out.reserve(text.size() / 4 * 3);
  for (std::size_t i = 0; i < text.size(); i += 4) {
    const bool last = i + 4 == text.size();
    const std::size_t data_chars = last ? 4 - pad : 4;
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < 4; ++k) {
      int d = 0;
      if (k < data_chars) {
        d = kDecode[static_cast<unsigned char>(text[i + k])];
        if (d < 0) {
          throw std::invalid_argument("base64: invalid character at offset " +
                                      std::to_string(i + k));
        }
      }
      v = (v << 6) | static_cast<std::uint32_t>(d);
    }
    out.push_back(static_cast<std::uint8_t>(v >> 16));
    if (data_chars >= 3) out.push_back(static_cast<std::uint8_t>(v >> 8));
    if (data_chars == 4) out.push_back(static_cast<std::uint8_t>(v));
  }
  return out;
}

}  // namespace beamcast::client
