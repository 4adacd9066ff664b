// Message framing of the Beamcast wire protocol (PROTOCOL.md, "Framing").
// Pure functions, no I/O: the server, the client and the fuzz targets share them.
//
//   offset 0  4 bytes  magic "BCP1"
//   offset 4  4 bytes  JSON length, unsigned big-endian
//   offset 8  4 bytes  binary length, unsigned big-endian
//   offset 12          JSON text (UTF-8, one object), then the binary attachments
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace beamcast {

inline constexpr std::size_t kFrameHeaderSize = 12;
inline constexpr char kFrameMagic[4] = {'B', 'C', 'P', '1'};

struct FrameHeader {
  std::uint32_t json_length = 0;
  std::uint32_t binary_length = 0;
  std::uint64_t body_length() const {
    return static_cast<std::uint64_t>(json_length) + binary_length;
  }
};

enum class HeaderStatus {
  kOk,
  kBadMagic,     // not a Beamcast frame: the stream cannot be resynchronized
  kEmptyJson,    // json_length == 0
  kTooLarge,     // body_length > the limit: the body can be skipped
};

HeaderStatus parse_frame_header(std::span<const std::uint8_t, kFrameHeaderSize> bytes,
                                std::uint64_t max_body_bytes, FrameHeader* out);

// Header + JSON + binary, ready to send.
std::vector<std::uint8_t> encode_frame(std::string_view json,
                                       std::span<const std::uint8_t> binary = {});

// An incremental decoder over a byte stream (used by the client and the fuzz
// target; the server reads header and body with two exact reads instead).
class FrameDecoder {
 public:
  explicit FrameDecoder(std::uint64_t max_body_bytes) : max_body_(max_body_bytes) {}

  struct Message {
    std::string json;
    std::vector<std::uint8_t> binary;
  };

  // Appends bytes; complete messages are queued for `next`.
  void feed(std::span<const std::uint8_t> bytes);
  // Pops the next complete message; false if none is complete yet.
  bool next(Message* out);
  // Set once the stream is broken (bad magic, empty JSON, too large); no
  // further messages are produced.
  HeaderStatus error() const { return error_; }

 private:
  std::uint64_t max_body_;
  std::vector<std::uint8_t> buffer_;
  std::size_t read_pos_ = 0;
  HeaderStatus error_ = HeaderStatus::kOk;
};

}  // namespace beamcast
