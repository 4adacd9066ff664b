// RFC 4648 base64 with padding: the PNGs of render responses with
// "encoding": "base64" (the server encodes, clients decode). nlohmann::json
// has no base64 of its own.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace beamcast {

std::string base64_encode(std::span<const std::uint8_t> bytes);
// Skips no characters: whitespace, URL-safe letters, bad padding or a
// truncated final group throw std::invalid_argument naming the offset.
std::vector<std::uint8_t> base64_decode(std::string_view text);

}  // namespace beamcast
