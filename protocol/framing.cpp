#include "protocol/framing.hpp"

#include <cstring>

namespace beamcast {
namespace {
std::uint32_t read_be32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}
void write_be32(std::uint8_t* p, std::uint32_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 24);
  p[1] = static_cast<std::uint8_t>(v >> 16);
  p[2] = static_cast<std::uint8_t>(v >> 8);
  p[3] = static_cast<std::uint8_t>(v);
}
}  // namespace

HeaderStatus parse_frame_header(std::span<const std::uint8_t, kFrameHeaderSize> bytes,
                                std::uint64_t max_body_bytes, FrameHeader* out) {
  if (std::memcmp(bytes.data(), kFrameMagic, 4) != 0) return HeaderStatus::kBadMagic;
  out->json_length = read_be32(bytes.data() + 4);
  out->binary_length = read_be32(bytes.data() + 8);
  if (out->json_length == 0) return HeaderStatus::kEmptyJson;
  if (out->body_length() > max_body_bytes) return HeaderStatus::kTooLarge;
  return HeaderStatus::kOk;
}

std::vector<std::uint8_t> encode_frame(std::string_view json, std::span<const std::uint8_t> binary) {
  std::vector<std::uint8_t> out(kFrameHeaderSize + json.size() + binary.size());
  std::memcpy(out.data(), kFrameMagic, 4);
  write_be32(out.data() + 4, static_cast<std::uint32_t>(json.size()));
  write_be32(out.data() + 8, static_cast<std::uint32_t>(binary.size()));
  std::memcpy(out.data() + kFrameHeaderSize, json.data(), json.size());
  if (!binary.empty()) {
    std::memcpy(out.data() + kFrameHeaderSize + json.size(), binary.data(), binary.size());
  }
  return out;
}

void FrameDecoder::feed(std::span<const std::uint8_t> bytes) {
  if (error_ != HeaderStatus::kOk) return;
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
}

bool FrameDecoder::next(Message* out) {
  if (error_ != HeaderStatus::kOk) return false;
  const std::size_t avail = buffer_.size() - read_pos_;
  if (avail < kFrameHeaderSize) return false;
  FrameHeader h;
  const HeaderStatus st = parse_frame_header(
      std::span<const std::uint8_t, kFrameHeaderSize>(buffer_.data() + read_pos_, kFrameHeaderSize),
      max_body_, &h);
  if (st != HeaderStatus::kOk) {
    error_ = st;
    return false;
  }
  if (avail < kFrameHeaderSize + h.body_length()) return false;
  const std::uint8_t* body = buffer_.data() + read_pos_ + kFrameHeaderSize;
  out->json.assign(reinterpret_cast<const char*>(body), h.json_length);
  out->binary.assign(body + h.json_length, body + h.body_length());
  read_pos_ += kFrameHeaderSize + h.body_length();
  // Compact once the consumed prefix dominates, keeping feed amortized O(n).
  if (read_pos_ > 65536 && read_pos_ * 2 > buffer_.size()) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(read_pos_));
    read_pos_ = 0;
  }
  return true;
}

}  // namespace beamcast
