// libFuzzer target: the BCP1 frame decoder (protocol/framing) over an arbitrary
// byte stream fed in arbitrary chunks. Besides "no crash, no sanitizer report",
// it checks that decoding is exact: re-encoding the decoded messages gives back
// the consumed bytes, and the decoder stops for good on a broken header.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>
#include <vector>

#include "fuzz/fuzz_support.hpp"
#include "protocol/framing.hpp"

using beamcast::FrameDecoder;
using beamcast::HeaderStatus;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  // Byte 0: the body limit (small limits reach kTooLarge); byte 1: the chunk size.
  static constexpr std::uint64_t kLimits[] = {0, 1, 16, 64, 4096, 1u << 20};
  const std::uint64_t limit = kLimits[data[0] % 6];
  const std::size_t chunk = 1 + data[1] % 64;
  const std::span<const std::uint8_t> stream(data + 2, size - 2);

  FrameDecoder decoder(limit);
  std::vector<std::uint8_t> reencoded;
  FrameDecoder::Message m;
  for (std::size_t pos = 0; pos < stream.size(); pos += chunk) {
    decoder.feed(stream.subspan(pos, std::min(chunk, stream.size() - pos)));
    while (decoder.next(&m)) {
      FUZZ_CHECK(!m.json.empty());
      FUZZ_CHECK(m.json.size() + m.binary.size() <= limit);
      const auto frame = beamcast::encode_frame(m.json, m.binary);
      reencoded.insert(reencoded.end(), frame.begin(), frame.end());
    }
  }
  // Every decoded message is exactly the next slice of the input.
  FUZZ_CHECK(reencoded.size() <= stream.size());
  FUZZ_CHECK(reencoded.empty() || std::memcmp(reencoded.data(), stream.data(), reencoded.size()) == 0);

  // After an error, nothing more is produced whatever arrives.
  if (decoder.error() != HeaderStatus::kOk) {
    const auto again = beamcast::encode_frame("{}");
    decoder.feed(again);
    FUZZ_CHECK(!decoder.next(&m));
  }

  // The one-shot header parser agrees with the decoder on the first header.
  if (stream.size() >= beamcast::kFrameHeaderSize) {
    beamcast::FrameHeader h;
    const HeaderStatus st = beamcast::parse_frame_header(
        std::span<const std::uint8_t, beamcast::kFrameHeaderSize>(stream.data(),
                                                                  beamcast::kFrameHeaderSize),
        limit, &h);
    if (st != HeaderStatus::kOk) FUZZ_CHECK(reencoded.empty() && decoder.error() == st);
  }
  return 0;
}
