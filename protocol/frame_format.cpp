#include "protocol/frame_format.hpp"

#include <zstd.h>

#include <stdexcept>

namespace beamcast {

const std::vector<std::string>& frame_format_names() {
  static const std::vector<std::string> names = {"png", "raw", "raw_zstd"};
  return names;
}

std::string_view frame_format_name(FrameFormat f) {
  return frame_format_names()[static_cast<std::size_t>(f)];
}

std::optional<FrameFormat> parse_frame_format(std::string_view name) {
  const auto& names = frame_format_names();
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return static_cast<FrameFormat>(i);
  }
  return std::nullopt;
}

namespace {

void check_layout(int width, int height, int bit_depth) {
  if (width <= 0 || height <= 0 || (bit_depth != 8 && bit_depth != 16)) {
    throw std::runtime_error("raw frame: bad layout " + std::to_string(width) + "x" +
                             std::to_string(height) + " at bit depth " +
                             std::to_string(bit_depth));
  }
}

}  // namespace

std::size_t raw_frame_bytes(int width, int height, int bit_depth) {
  check_layout(width, height, bit_depth);
  return 3 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height) *
         static_cast<std::size_t>(bit_depth / 8);
}

std::vector<std::uint8_t> encode_raw_frame(std::span<const std::uint16_t> rgb, int bit_depth,
                                           FrameFormat format, int zstd_level) {
  if (format == FrameFormat::kPng) throw std::invalid_argument("encode_raw_frame: not a raw format");
  if (bit_depth != 8 && bit_depth != 16) throw std::invalid_argument("raw frame: bit depth");
  std::vector<std::uint8_t> raw(rgb.size() * static_cast<std::size_t>(bit_depth / 8));
  if (bit_depth == 8) {
    for (std::size_t i = 0; i < rgb.size(); ++i) raw[i] = static_cast<std::uint8_t>(rgb[i]);
  } else {
    for (std::size_t i = 0; i < rgb.size(); ++i) {
      raw[2 * i] = static_cast<std::uint8_t>(rgb[i] & 0xff);
      raw[2 * i + 1] = static_cast<std::uint8_t>(rgb[i] >> 8);
    }
  }
  if (format == FrameFormat::kRaw) return raw;
  // One context per thread: creating one costs more than packing a small frame.
  thread_local struct Ctx {
    ZSTD_CCtx* c = ZSTD_createCCtx();
    ~Ctx() { ZSTD_freeCCtx(c); }
  } ctx;
  std::vector<std::uint8_t> packed(ZSTD_compressBound(raw.size()));
  const std::size_t n =
      ZSTD_compressCCtx(ctx.c, packed.data(), packed.size(), raw.data(), raw.size(), zstd_level);
  if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
  packed.resize(n);
  return packed;
}

std::vector<std::uint16_t> decode_raw_frame(std::span<const std::uint8_t> bytes, int width,
                                            int height, int bit_depth, FrameFormat format) {
  const std::size_t expected = raw_frame_bytes(width, height, bit_depth);
  std::vector<std::uint8_t> unpacked;
  std::span<const std::uint8_t> raw = bytes;
  if (format == FrameFormat::kRawZstd) {
    // The frame header states the size: checked before any memory is taken.
    const unsigned long long size = ZSTD_getFrameContentSize(bytes.data(), bytes.size());
    if (size != expected) {
      throw std::runtime_error("raw_zstd frame: content size " +
                               (size == ZSTD_CONTENTSIZE_UNKNOWN || size == ZSTD_CONTENTSIZE_ERROR
                                    ? std::string("unknown or invalid")
                                    : std::to_string(size)) +
                               ", expected " + std::to_string(expected) + " bytes");
    }
    unpacked.resize(expected);
    const std::size_t n = ZSTD_decompress(unpacked.data(), unpacked.size(), bytes.data(), bytes.size());
    if (ZSTD_isError(n) || n != expected) {
      throw std::runtime_error(std::string("raw_zstd frame: ") +
                               (ZSTD_isError(n) ? ZSTD_getErrorName(n) : "short content"));
    }
    raw = unpacked;
  } else if (format != FrameFormat::kRaw) {
    throw std::invalid_argument("decode_raw_frame: not a raw format");
  }
  if (raw.size() != expected) {
    throw std::runtime_error("raw frame: " + std::to_string(raw.size()) + " bytes, expected " +
                             std::to_string(expected));
  }
  const std::size_t samples = expected / static_cast<std::size_t>(bit_depth / 8);
  std::vector<std::uint16_t> rgb(samples);
  if (bit_depth == 8) {
    for (std::size_t i = 0; i < samples; ++i) rgb[i] = raw[i];
  } else {
    for (std::size_t i = 0; i < samples; ++i) {
      rgb[i] = static_cast<std::uint16_t>(raw[2 * i] | (raw[2 * i + 1] << 8));
    }
  }
  return rgb;
}

}  // namespace beamcast
