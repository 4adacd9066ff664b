// Frame encoders and formats (PROTOCOL.md, "Frame formats"; issue 39): every
// encoder the server can use decodes to the very samples it was given (PNG
// with libpng's decoder), raw frames are checked against their size, and the
// C++ client unpacks raw and raw_zstd frames of a render response.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <vector>

#include "client/client.hpp"
#include "protocol/frame_format.hpp"
#include "render/image.hpp"
#include "server/threads.hpp"

namespace beamcast {
namespace {

// Noise in the low bits over smooth gradients: both the filters' easy case and
// their hard one, every sample value reachable.
Image test_image(int w, int h, int bit_depth, unsigned seed) {
  Image img{w, h, bit_depth, std::vector<std::uint16_t>(3 * static_cast<std::size_t>(w) * h)};
  const int maxv = bit_depth == 16 ? 65535 : 255;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> any(0, maxv), small(-3, 3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) {
        const std::size_t i = 3 * (static_cast<std::size_t>(y) * w + x) + c;
        const int smooth = (x * 37 + y * 11 + c * 50) * maxv / (w * 37 + h * 11 + 150);
        const int v = (x + y) % 7 == 0 ? any(rng) : smooth + small(rng);
        img.rgb[i] = static_cast<std::uint16_t>(std::clamp(v, 0, maxv));
      }
    }
  }
  return img;
}

const std::vector<Image>& images() {
  static const std::vector<Image> all = [] {
    std::vector<Image> v;
    for (int depth : {8, 16}) {
      v.push_back(test_image(1, 1, depth, 1));
      v.push_back(test_image(7, 5, depth, 2));
      v.push_back(test_image(97, 64, depth, 3));
    }
    return v;
  }();
  return all;
}

TEST(FrameEncoders, LibdeflatePngDecodesToTheSameSamples) {
  for (const Image& img : images()) {
    for (PngRowFilter f : {PngRowFilter::kNone, PngRowFilter::kSub, PngRowFilter::kUp}) {
      for (int level : {0, 1, 6, 12}) {
        const Image back = decode_png(encode_png_libdeflate(img, level, f));
        ASSERT_EQ(back.width, img.width);
        ASSERT_EQ(back.height, img.height);
        ASSERT_EQ(back.bit_depth, img.bit_depth);
        ASSERT_EQ(back.rgb, img.rgb) << img.width << "x" << img.height << " at " << img.bit_depth
                                     << " bits, filter " << static_cast<int>(f) << ", level "
                                     << level;
      }
    }
  }
}

TEST(FrameEncoders, EverySettingOfTheServerIsLossless) {
  for (const Image& img : images()) {
    for (PngEncoder e : {PngEncoder::kLibdeflate, PngEncoder::kLibpng}) {
      PngSettings s;
      s.encoder = e;
      s.level = e == PngEncoder::kLibpng ? 2 : 1;  // the old and the new default
      EXPECT_EQ(decode_png(encode_png(img, s)).rgb, img.rgb);
    }
    for (FrameFormat f : {FrameFormat::kRaw, FrameFormat::kRawZstd}) {
      const auto bytes = encode_raw_frame(img.rgb, img.bit_depth, f);
      if (f == FrameFormat::kRaw) {
        EXPECT_EQ(bytes.size(), raw_frame_bytes(img.width, img.height, img.bit_depth));
      }
      EXPECT_EQ(decode_raw_frame(bytes, img.width, img.height, img.bit_depth, f), img.rgb);
    }
  }
}

TEST(FrameFormats, RawLayoutIsRgbLittleEndian) {
  const Image img{2, 1, 16, {0x0102, 0x0304, 0x0506, 0xA0B0, 0xC0D0, 0xE0F0}};
  EXPECT_EQ(encode_raw_frame(img.rgb, 16, FrameFormat::kRaw),
            (std::vector<std::uint8_t>{2, 1, 4, 3, 6, 5, 0xB0, 0xA0, 0xD0, 0xC0, 0xF0, 0xE0}));
  EXPECT_EQ(encode_raw_frame(std::vector<std::uint16_t>{1, 2, 255}, 8, FrameFormat::kRaw),
            (std::vector<std::uint8_t>{1, 2, 255}));
}

TEST(FrameFormats, WrongSizesAreRefused) {
  const Image& img = images()[1];  // 7x5, 8-bit
  const auto raw = encode_raw_frame(img.rgb, 8, FrameFormat::kRaw);
  const auto packed = encode_raw_frame(img.rgb, 8, FrameFormat::kRawZstd);
  EXPECT_THROW(decode_raw_frame(raw, 7, 6, 8, FrameFormat::kRaw), std::runtime_error);
  EXPECT_THROW(decode_raw_frame(raw, 7, 5, 16, FrameFormat::kRaw), std::runtime_error);
  // The zstd frame's stated size is checked before anything is unpacked.
  EXPECT_THROW(decode_raw_frame(packed, 7, 6, 8, FrameFormat::kRawZstd), std::runtime_error);
  EXPECT_THROW(decode_raw_frame(raw, 7, 5, 8, FrameFormat::kRawZstd), std::runtime_error);
  std::vector<std::uint8_t> cut(packed.begin(), packed.end() - 4);
  EXPECT_THROW(decode_raw_frame(cut, 7, 5, 8, FrameFormat::kRawZstd), std::runtime_error);
}

TEST(FrameFormats, NamesRoundTrip) {
  for (const std::string& n : frame_format_names()) {
    ASSERT_TRUE(parse_frame_format(n));
    EXPECT_EQ(frame_format_name(*parse_frame_format(n)), n);
  }
  EXPECT_FALSE(parse_frame_format("webp"));
  EXPECT_FALSE(parse_frame_format("RAW"));
}

// The C++ client unpacks raw frames of a response and refuses one whose bytes
// do not match its size.
TEST(FrameFormats, ClientReadsRawAndZstdFrames) {
  const Image& img = images()[4];  // 7x5, 16-bit
  for (FrameFormat f : {FrameFormat::kRaw, FrameFormat::kRawZstd}) {
    client::Response r;
    r.ok = true;
    r.binary = encode_raw_frame(img.rgb, 16, f);
    const std::string name(frame_format_name(f));
    r.json = {{"id", 1},
              {"ok", true},
              {"result",
               {{"passes", {"beams"}},
                {"frames",
                 {{{"camera", "v"}, {"index", 0}, {"width", 7}, {"height", 5}, {"format", name},
                   {"bit_depth", 16}, {"attachment", {{"offset", 0}, {"length", r.binary.size()}}},
                   {"gpu_ms", 1.0}, {"pass_ms", {{"beams", 1.0}}}, {"readback_ms", 0.1},
                   {"encode_ms", 0.2},
                   {"gpu_batch", {{"index", 0}, {"views", 1}, {"gpu_ms", 1.0}, {"readback_ms", 0.1}}}}}},
                {"batched", false},
                {"batch", {{"requests", 1}, {"views", 1}}},
                {"timings",
                 {{"queue_ms", 0}, {"render_ms", 1}, {"readback_ms", 0}, {"encode_ms", 0},
                  {"server_ms", 2}}}}}};
    const auto frames = client::decode_frames(r);
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_EQ(frames[0].format, name);
    EXPECT_EQ(frames[0].samples, img.rgb);
    r.json["result"]["frames"][0]["height"] = 6;
    EXPECT_THROW(client::decode_frames(r), std::runtime_error) << name;
  }
}

TEST(EncodeThreads, DefaultIsTheCoresLessRenderAndNetworkAtLeastTwo) {
  EXPECT_EQ(default_encode_threads(16, 1, 1), 14);
  EXPECT_EQ(default_encode_threads(16, 2, 4), 10);
  EXPECT_EQ(default_encode_threads(2, 1, 1), 2);
  EXPECT_EQ(default_encode_threads(1, 1, 1), 2);
  EXPECT_GE(usable_cores(), 1);
}

}  // namespace
}  // namespace beamcast
