// Frame formats a client may negotiate in `hello` (PROTOCOL.md, "Frame
// formats"): PNG (the default), or for batch clients that decode anyway the
// frame's samples as they are ("raw"), optionally zstd-packed ("raw_zstd").
// The raw layout and its checks live here so the server, the C++ client and
// the tests share one definition. Pure: no GL, no sockets.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace beamcast {

enum class FrameFormat { kPng, kRaw, kRawZstd };

// "png", "raw", "raw_zstd": the wire names, in this order.
const std::vector<std::string>& frame_format_names();
std::string_view frame_format_name(FrameFormat f);
std::optional<FrameFormat> parse_frame_format(std::string_view name);

// Bytes of a raw frame: rows from the top down, R, G, B per pixel (frames
// have no alpha), one byte a sample at bit depth 8, two little-endian bytes
// at bit depth 16.
std::size_t raw_frame_bytes(int width, int height, int bit_depth);

// Samples (0..255 or 0..65535, 3 per pixel) to the raw layout, and, for
// "raw_zstd", one zstd frame of it (level: zstd's, 1 by default; measured in
// docs/performance.md, "Frame encoders").
std::vector<std::uint8_t> encode_raw_frame(std::span<const std::uint16_t> rgb, int bit_depth,
                                           FrameFormat format, int zstd_level = 1);

// The samples of a raw or raw_zstd frame of the given size; throws
// std::runtime_error when the bytes are not exactly one such frame (a zstd
// frame is checked against the expected size before it is unpacked).
std::vector<std::uint16_t> decode_raw_frame(std::span<const std::uint8_t> bytes, int width,
                                            int height, int bit_depth, FrameFormat format);

}  // namespace beamcast
