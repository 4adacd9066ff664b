// render/video.hpp: the preview's VP8/VP9 stream (issue 42).
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "render/video.hpp"

namespace beamcast {
namespace {

// A smooth picture with a bright disc that moves with `t`: what a camera
// drag shows, in a few pixels.
Image moving_picture(int w, int h, int t, int bit_depth = 8) {
  Image img;
  img.width = w;
  img.height = h;
  img.bit_depth = bit_depth;
  img.rgb.resize(3 * static_cast<std::size_t>(w) * h);
  const double cx = 0.3 * w + 2.0 * t, cy = 0.5 * h;
  const int scale = bit_depth == 16 ? 257 : 1;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double d = std::hypot(x - cx, y - cy);
      const double disc = std::exp(-d * d / (0.02 * w * w));
      std::uint16_t* p = &img.rgb[3 * (static_cast<std::size_t>(y) * w + x)];
      p[0] = static_cast<std::uint16_t>(scale * std::lround(40 + 200 * disc));
      p[1] = static_cast<std::uint16_t>(scale * std::lround(30 + 120 * disc + 60.0 * y / h));
      p[2] = static_cast<std::uint16_t>(scale * std::lround(60 + 100.0 * x / w));
    }
  }
  return img;
}

class VideoCodecs : public ::testing::TestWithParam<VideoCodec> {};

// Encode 12 frames of a moving picture and decode them: the first and the
// forced one are key frames and the rest not; each decoded picture is within
// 30 dB PSNR of its source (measured: 42-48 dB at 1 Mbit/s for these 96x64
// frames; 30 dB is the level where such a picture shows no visible blocks,
// and a colour-matrix or plane mix-up gives 10-20 dB).
TEST_P(VideoCodecs, EncodesKeyFramesOnlyAtStartAndOnRequestAndDecodesClose) {
  const VideoCodec codec = GetParam();
  VideoEncoder enc({codec, 96, 64, 1000, 1});
  VideoDecoder dec(codec);
  for (int t = 0; t < 12; ++t) {
    const Image src = moving_picture(96, 64, t, t % 2 ? 16 : 8);
    const EncodedVideoFrame f = enc.encode(src, 33.0 * t, t == 7);
    EXPECT_EQ(f.key, t == 0 || t == 7) << "frame " << t;
    EXPECT_EQ(f.pts, t);
    const std::vector<std::uint8_t> packed = pack_video_frame(f, codec);
    const VideoFrameView v = unpack_video_frame(packed);
    EXPECT_EQ(v.key, f.key);
    EXPECT_EQ(v.codec, codec);
    EXPECT_EQ(v.pts, static_cast<std::uint32_t>(t));
    ASSERT_EQ(v.data.size(), f.data.size());
    const Image out = dec.decode(v.data);
    ASSERT_EQ(out.width, 96);
    ASSERT_EQ(out.height, 64);
    Image src8 = src;
    src8.bit_depth = 8;
    if (src.bit_depth == 16) {
      for (auto& s : src8.rgb) s = static_cast<std::uint16_t>(s >> 8);
    }
    EXPECT_GT(compare_levels(out, src8).psnr_db, 30.0) << "frame " << t;
  }
}

INSTANTIATE_TEST_SUITE_P(Vpx, VideoCodecs, ::testing::Values(VideoCodec::kVp8, VideoCodec::kVp9),
                         [](const auto& info) { return std::string(video_codec_name(info.param)); });

TEST(VideoFrames, OddSizesAndBitrateChangesEncode) {
  VideoEncoder enc({VideoCodec::kVp8, 33, 17, 200, 1});
  VideoDecoder dec(VideoCodec::kVp8);
  for (int t = 0; t < 4; ++t) {
    if (t == 2) enc.set_bitrate(3000);
    const Image out = dec.decode(enc.encode(moving_picture(33, 17, t), 40.0 * t).data);
    EXPECT_EQ(out.width, 33);
    EXPECT_EQ(out.height, 17);
  }
}

TEST(VideoFrames, RejectsWhatIsNotAFrame) {
  EXPECT_THROW(unpack_video_frame(std::vector<std::uint8_t>{'B', 'C', 'V'}), std::runtime_error);
  std::vector<std::uint8_t> bad(20, 0);
  EXPECT_THROW(unpack_video_frame(bad), std::runtime_error);
  // A decoder given garbage says so; it does not crash.
  VideoDecoder dec(VideoCodec::kVp8);
  EXPECT_THROW(dec.decode(std::vector<std::uint8_t>(5, 0xff)), std::runtime_error);
}

}  // namespace
}  // namespace beamcast
