// render/video.hpp: the preview's VP8/VP9/AV1 stream (issue 42).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>
#include <span>
#include <stdexcept>
#include <utility>

#include <aom/aom_decoder.h>
#include <aom/aom_image.h>
#include <aom/aomdx.h>
#include <vpx/vp8dx.h>
#include <vpx/vpx_decoder.h>

#include "protocol/check.hpp"
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

INSTANTIATE_TEST_SUITE_P(Codecs, VideoCodecs,
                         ::testing::Values(VideoCodec::kVp8, VideoCodec::kVp9, VideoCodec::kAv1),
                         [](const auto& info) { return std::string(video_codec_name(info.param)); });

TEST(VideoFrames, OddSizesAndBitrateChangesEncode) {
  for (VideoCodec c : {VideoCodec::kVp8, VideoCodec::kAv1}) {
    VideoEncoder enc({c, 33, 17, 200, 1});
    VideoDecoder dec(c);
    for (int t = 0; t < 4; ++t) {
      if (t == 2) enc.set_bitrate(3000);
      const Image out = dec.decode(enc.encode(moving_picture(33, 17, t), 40.0 * t).data);
      EXPECT_EQ(out.width, 33) << video_codec_name(c);
      EXPECT_EQ(out.height, 17) << video_codec_name(c);
    }
    EXPECT_EQ(enc.settings().bitrate_kbps, 3000);
  }
}

// Noise, so that a swapped channel, plane, row or block edge shows; the
// first six pixels black, white, red, green, blue and yellow (the range's
// ends). 16-bit samples have a random low byte (the conversion keeps the
// high one).
Image noise_picture(int w, int h, int depth) {
  Image img;
  img.width = w;
  img.height = h;
  img.bit_depth = depth;
  img.rgb.resize(3 * static_cast<std::size_t>(w) * h);
  std::uint32_t state = 12345u + static_cast<std::uint32_t>(w * 131 + h * 7 + depth);
  for (auto& v : img.rgb) {
    state = state * 1664525u + 1013904223u;
    v = static_cast<std::uint16_t>(depth == 16 ? state >> 16 : state >> 24);
  }
  const int ends[][3] = {{0, 0, 0},   {255, 255, 255}, {255, 0, 0},
                         {0, 255, 0}, {0, 0, 255},     {255, 255, 0}};
  for (std::size_t i = 0; i < std::min<std::size_t>(6, img.rgb.size() / 3); ++i) {
    for (int c = 0; c < 3; ++c) {
      img.rgb[3 * i + static_cast<std::size_t>(c)] =
          static_cast<std::uint16_t>(depth == 16 ? ends[i][c] * 257 : ends[i][c]);
    }
  }
  return img;
}

// A colour conversion against the matrix evaluated pixel by pixel from its
// definition: `convert(img, y, u, v, y_stride, u_stride, v_stride)` fills
// planes of `Sample`; Y of each pixel, U and V of the mean of each 2x2 block
// (or of what an odd edge leaves; rounded to integers where `rounded_mean`,
// as rgb_to_i420 does, exact otherwise), each within `tolerance` of
// want_y/u/v(r, g, b) of the 8-bit samples. Odd and even sizes, one-pixel
// rows and columns, 8- and 16-bit samples, planes with padded strides.
template <class Sample, class Convert, class Y, class U, class V>
void expect_conversion(Convert convert, bool rounded_mean, Y want_y, U want_u, V want_v,
                       double tolerance) {
  for (const int w : {1, 2, 3, 17, 64}) {
    for (const int h : {1, 2, 5, 33}) {
      for (const int depth : {8, 16}) {
        const Image img = noise_picture(w, h, depth);
        const int cw = (w + 1) / 2, ch = (h + 1) / 2;
        std::vector<Sample> y(static_cast<std::size_t>(w + 3) * h),
            u(static_cast<std::size_t>(cw + 1) * ch), v(static_cast<std::size_t>(cw + 2) * ch);
        convert(img, y.data(), u.data(), v.data(), w + 3, cw + 1, cw + 2);
        auto sample = [&](int x, int yy, int c) {
          return img.rgb[3 * (static_cast<std::size_t>(yy) * w + x) + c] >> (depth == 16 ? 8 : 0);
        };
        for (int yy = 0; yy < h; ++yy) {
          for (int x = 0; x < w; ++x) {
            ASSERT_NEAR(y[static_cast<std::size_t>(yy) * (w + 3) + x],
                        want_y(sample(x, yy, 0), sample(x, yy, 1), sample(x, yy, 2)), tolerance)
                << w << "x" << h << " depth " << depth << " Y at " << x << "," << yy;
          }
        }
        for (int cy = 0; cy < ch; ++cy) {
          for (int cx = 0; cx < cw; ++cx) {
            int sum[3] = {0, 0, 0}, n = 0;
            for (int yy = 2 * cy; yy < std::min(h, 2 * cy + 2); ++yy) {
              for (int x = 2 * cx; x < std::min(w, 2 * cx + 2); ++x) {
                for (int c = 0; c < 3; ++c) sum[c] += sample(x, yy, c);
                ++n;
              }
            }
            double mean[3];
            for (int c = 0; c < 3; ++c) {
              mean[c] = rounded_mean ? (sum[c] + n / 2) / n : static_cast<double>(sum[c]) / n;
            }
            ASSERT_NEAR(u[static_cast<std::size_t>(cy) * (cw + 1) + cx], want_u(mean[0], mean[1], mean[2]),
                        tolerance)
                << w << "x" << h << " depth " << depth << " U at " << cx << "," << cy;
            ASSERT_NEAR(v[static_cast<std::size_t>(cy) * (cw + 2) + cx], want_v(mean[0], mean[1], mean[2]),
                        tolerance)
                << w << "x" << h << " depth " << depth << " V at " << cx << "," << cy;
          }
        }
      }
    }
  }
}

// rgb_to_i420 in `range`, the mean of a 2x2 block rounded to integers.
template <class Y, class U, class V>
void expect_i420(ColorRange range, Y want_y, U want_u, V want_v, double tolerance) {
  expect_conversion<std::uint8_t>(
      [range](const Image& img, std::uint8_t* y, std::uint8_t* u, std::uint8_t* v, int ys, int us, int vs) {
        rgb_to_i420(img, {y, u, v, ys, us, vs}, range);
      },
      true, want_y, want_u, want_v, tolerance);
}

// Limited range (VP8's) against the integer form of the BT.601
// limited-range matrix, exactly: the fast row form must give the same bytes.
TEST(VideoFrames, ConversionMatchesTheMatrix) {
  expect_i420(
      ColorRange::kLimited,
      [](int r, int g, int b) { return ((66 * r + 129 * g + 25 * b + 128) >> 8) + 16; },
      [](int r, int g, int b) { return ((-38 * r - 74 * g + 112 * b + 128) >> 8) + 128; },
      [](int r, int g, int b) { return ((112 * r - 94 * g - 18 * b + 128) >> 8) + 128; }, 0.0);
}

// Full range (AV1's and VP9's) against the BT.601 matrix in floating point,
// JPEG's YCbCr, U and V clamped to 0-255: each sample is the matrix's value
// rounded, within 0.51 (the 16-bit coefficients move a value by at most
// 0.002, which can tip a rounding at .5).
TEST(VideoFrames, FullRangeConversionMatchesTheMatrix) {
  expect_i420(
      ColorRange::kFull, [](int r, int g, int b) { return 0.299 * r + 0.587 * g + 0.114 * b; },
      [](int r, int g, int b) {
        return std::clamp(128.0 - 0.168736 * r - 0.331264 * g + 0.5 * b, 0.0, 255.0);
      },
      [](int r, int g, int b) {
        return std::clamp(128.0 + 0.5 * r - 0.418688 * g - 0.081312 * b, 0.0, 255.0);
      },
      0.51);
}

// An AV1 stream says what its samples are: full range, the BT.601 matrix,
// BT.709 (sRGB) primaries and the sRGB transfer, so that a browser's
// VideoFrame converts back with the matrix the encoder used; a VP9 stream
// says full range and BT.601 (all its headers can say). The decoder turns
// full-range pictures back to RGB close to the source (near-lossless
// bitrate: within 1.5 levels RMS on black, white and grey; a range read as
// limited would stretch black to -19 and white to 278), and VP8's
// limited-range ones too.
TEST(VideoFrames, StreamsAreFullRangeBt601AndSaySo) {
  VideoEncoder enc({VideoCodec::kAv1, 64, 48, 8000, 1, 0, 0.0, 10});
  const EncodedVideoFrame f = enc.encode(moving_picture(64, 48, 0), 0.0);
  aom_codec_ctx_t ctx{};
  aom_codec_dec_cfg_t cfg{};
  cfg.threads = 1;
  ASSERT_EQ(aom_codec_dec_init(&ctx, aom_codec_av1_dx(), &cfg, 0), AOM_CODEC_OK);
  ASSERT_EQ(aom_codec_decode(&ctx, f.data.data(), f.data.size(), nullptr), AOM_CODEC_OK);
  aom_codec_iter_t iter = nullptr;
  const aom_image_t* img = aom_codec_get_frame(&ctx, &iter);
  ASSERT_NE(img, nullptr);
  EXPECT_EQ(img->range, AOM_CR_FULL_RANGE);
  EXPECT_EQ(img->mc, AOM_CICP_MC_BT_601);
  EXPECT_EQ(img->cp, AOM_CICP_CP_BT_709);
  EXPECT_EQ(img->tc, AOM_CICP_TC_SRGB);
  EXPECT_EQ(img->bit_depth, 10u);
  EXPECT_EQ(img->fmt, AOM_IMG_FMT_I42016);
  aom_codec_destroy(&ctx);

  VideoEncoder vp9_enc({VideoCodec::kVp9, 64, 48, 8000, 1});
  const EncodedVideoFrame f9 = vp9_enc.encode(moving_picture(64, 48, 0), 0.0);
  vpx_codec_ctx_t vctx{};
  vpx_codec_dec_cfg_t vcfg{};
  vcfg.threads = 1;
  ASSERT_EQ(vpx_codec_dec_init(&vctx, vpx_codec_vp9_dx(), &vcfg, 0), VPX_CODEC_OK);
  ASSERT_EQ(vpx_codec_decode(&vctx, f9.data.data(), static_cast<unsigned>(f9.data.size()), nullptr, 0),
            VPX_CODEC_OK);
  vpx_codec_iter_t viter = nullptr;
  const vpx_image_t* vimg = vpx_codec_get_frame(&vctx, &viter);
  ASSERT_NE(vimg, nullptr);
  EXPECT_EQ(vimg->range, VPX_CR_FULL_RANGE);
  EXPECT_EQ(vimg->cs, VPX_CS_BT_601);
  vpx_codec_destroy(&vctx);

  for (const auto& [c, bits] : {std::pair{VideoCodec::kAv1, 10}, std::pair{VideoCodec::kAv1, 8},
                                std::pair{VideoCodec::kVp9, 8}, std::pair{VideoCodec::kVp8, 8}}) {
    for (const int level : {0, 128, 255}) {
      VideoEncoder flat_enc({c, 64, 48, 8000, 1, 0, 0.0, bits});
      VideoDecoder dec(c);
      Image flat;
      flat.width = 64;
      flat.height = 48;
      flat.bit_depth = 8;
      flat.rgb.assign(3 * 64 * 48, static_cast<std::uint16_t>(level));
      const Image out = dec.decode(flat_enc.encode(flat, 0.0).data);
      double sq = 0.0;
      for (std::size_t i = 0; i < out.rgb.size(); ++i) sq += std::pow(out.rgb[i] - level, 2);
      EXPECT_LT(std::sqrt(sq / static_cast<double>(out.rgb.size())), 1.5)
          << video_codec_name(c) << " " << bits << " bits, grey level " << level;
    }
  }
}

// AV1's and VP9's rate control starts near the quantizer its bitrate
// affords: with a bitrate that lets the key frame take the finest
// quantizer, the delta frames after it stay at or under 24 (the encoder
// opens with 24 as the worst, which starts the rate control's average
// there, and widens it to 56 before the first frame) instead of jumping to
// the worst allowed and climbing down 1/8 a frame (with 56 from the start:
// 36-41 here). A low bitrate still gets coarse quantizers: the range is 56
// wide.
class RateControlStart : public ::testing::TestWithParam<VideoCodec> {};

TEST_P(RateControlStart, StartsAtAQuantizerItsBitrateAffords) {
  const VideoCodec codec = GetParam();
  VideoEncoder rich({codec, 128, 96, 3000, 1, codec == VideoCodec::kAv1 ? 5 : 8});
  std::vector<int> q;
  for (int t = 0; t < 8; ++t)
    q.push_back(rich.encode(moving_picture(128, 96, t), 33.0 * t).quantizer);
  for (int t = 1; t < 8; ++t) EXPECT_LE(q[static_cast<std::size_t>(t)], 24) << "frame " << t;
  // Noise over the picture, new every frame: what no bitrate of 20 kbit/s
  // codes finely.
  VideoEncoder poor({codec, 128, 96, 20, 1, codec == VideoCodec::kAv1 ? 5 : 8});
  std::uint32_t state = 99u;
  int last = -1;
  for (int t = 0; t < 20; ++t) {
    Image img = moving_picture(128, 96, t);
    for (auto& s : img.rgb) {
      state = state * 1664525u + 1013904223u;
      s = static_cast<std::uint16_t>(
          std::clamp(static_cast<int>(s) + static_cast<int>(state >> 27) - 16, 0, 255));
    }
    last = poor.encode(img, 33.0 * t).quantizer;
  }
  EXPECT_GT(last, 24);
  EXPECT_LE(last, 56);
}

INSTANTIATE_TEST_SUITE_P(Codecs, RateControlStart,
                         ::testing::Values(VideoCodec::kAv1, VideoCodec::kVp9),
                         [](const auto& info) { return std::string(video_codec_name(info.param)); });

// One encoder thread per started 2^19 pixels (2^17 at 10 bits), at most 4
// and at most the cores: the preview's 512x512 stays on one thread at 8
// bits and gets 2 at 10, 1080p gets 4 (2 here).
TEST(VideoFrames, EncoderThreadsFollowThePictureSize) {
  EXPECT_EQ(video_encoder_threads(512, 512, 16), 1);
  EXPECT_EQ(video_encoder_threads(1280, 720, 16), 2);
  EXPECT_EQ(video_encoder_threads(1920, 1080, 16), 4);
  EXPECT_EQ(video_encoder_threads(1920, 1080, 2), 2);
  EXPECT_EQ(video_encoder_threads(3840, 2160, 64), 4);
  EXPECT_EQ(video_encoder_threads(1, 1, 0), 1);
  // 10 bits: one per started 2^17 pixels.
  EXPECT_EQ(video_encoder_threads(512, 512, 16, 10), 2);
  EXPECT_EQ(video_encoder_threads(512, 512, 1, 10), 1);
  EXPECT_EQ(video_encoder_threads(256, 256, 16, 10), 1);
  EXPECT_EQ(video_encoder_threads(1024, 512, 16, 10), 4);
  // A stream encoded with threads gives the same pictures' sizes back.
  VideoEncoder enc({VideoCodec::kVp9, 600, 340, 1000, 2});
  VideoDecoder dec(VideoCodec::kVp9);
  const Image out = dec.decode(enc.encode(moving_picture(600, 340, 0), 0.0).data);
  EXPECT_EQ(out.width, 600);
  EXPECT_EQ(out.height, 340);
}

TEST(VideoFrames, RejectsWhatIsNotAFrame) {
  EXPECT_THROW(unpack_video_frame(std::vector<std::uint8_t>{'B', 'C', 'V'}), std::runtime_error);
  std::vector<std::uint8_t> bad(20, 0);
  EXPECT_THROW(unpack_video_frame(bad), std::runtime_error);
  // A codec byte past the last codec (av1, 2) is not a frame.
  std::vector<std::uint8_t> unknown_codec = {'B', 'C', 'V', '1', 0, 3, 0, 0, 0, 0, 0, 0, 1};
  EXPECT_THROW(unpack_video_frame(unknown_codec), std::runtime_error);
  unknown_codec[5] = 2;
  EXPECT_EQ(unpack_video_frame(unknown_codec).codec, VideoCodec::kAv1);
  // Bands: a count of 1 or over 16, a table cut short, bands longer than
  // the frame or bytes after them, a nonzero byte 7.
  std::vector<std::uint8_t> banded = {'B', 'C', 'V', '1', 0, 2, 2, 0, 0, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 7, 7, 7};
  const VideoFrameView v = unpack_video_frame(banded);
  ASSERT_EQ(v.bands.size(), 2u);
  EXPECT_EQ(v.bands[0].size(), 2u);
  EXPECT_EQ(v.bands[1].size(), 1u);
  for (const auto& [at, value] : std::vector<std::pair<std::size_t, std::uint8_t>>{
           {6, 1}, {6, 17}, {7, 1}, {16, 2}, {12, 1}}) {
    std::vector<std::uint8_t> bad_bands = banded;
    bad_bands[at] = value;
    EXPECT_THROW(unpack_video_frame(bad_bands), std::runtime_error) << at << " " << int{value};
  }
  EXPECT_THROW(unpack_video_frame(std::span(banded).first(15)), std::runtime_error);
  // A decoder given garbage says so; it does not crash.
  for (VideoCodec c : {VideoCodec::kVp8, VideoCodec::kVp9, VideoCodec::kAv1}) {
    VideoDecoder dec(c);
    EXPECT_THROW(dec.decode(std::vector<std::uint8_t>(5, 0xff)), std::runtime_error)
        << video_codec_name(c);
  }
}

// An 8-bit AV1 stream's speed follows its encode time: with a bound no frame meets
// (1 ns) it goes one step faster after every 3 delta frames up to 9 and stays
// there; with a bound every frame meets by far it comes back a step per 3
// delta frames to the speed it started at, and no lower. Key frames are not
// counted; VP9 does not adapt. Each frame reports the speed it was encoded at.
TEST(VideoFrames, Av1SpeedFollowsTheEncodeTime) {
  VideoEncoder enc({VideoCodec::kAv1, 64, 48, 500, 1, 5, 1e-6});
  VideoDecoder dec(VideoCodec::kAv1);
  std::vector<int> speeds;
  for (int t = 0; t < 16; ++t) {
    const EncodedVideoFrame f = enc.encode(moving_picture(64, 48, t), 33.0 * t, t == 8);
    speeds.push_back(f.speed);
    EXPECT_EQ(dec.decode(f.data).width, 64);
  }
  // Frame 0 and 8 are key frames: 1-3 at 5, 4-6 at 6, 7 and 9-10 at 7, ...
  EXPECT_EQ(speeds, (std::vector<int>{5, 5, 5, 5, 6, 6, 6, 7, 7, 7, 7, 8, 8, 8, 9, 9}));
  enc.set_max_encode_ms(1e9);
  speeds.clear();
  for (int t = 16; t < 32; ++t) speeds.push_back(enc.encode(moving_picture(64, 48, t), 33.0 * t).speed);
  // Frames 14 and 15 were already timed at 9: the third, frame 16, decides.
  EXPECT_EQ(speeds, (std::vector<int>{9, 8, 8, 8, 7, 7, 7, 6, 6, 6, 5, 5, 5, 5, 5, 5}));
  VideoEncoder vp9({VideoCodec::kVp9, 64, 48, 500, 1, 8, 1e-6});
  for (int t = 0; t < 8; ++t) EXPECT_EQ(vp9.encode(moving_picture(64, 48, t), 33.0 * t).speed, 8);
}

// rgb_to_i010 against the BT.601 full-range matrix in floating point on the
// 10-bit scale (x 1023/255): Y of each pixel, U and V of the exact mean of
// each 2x2 block (or of what an odd edge leaves), centred on 512 and clamped
// to 0-1023; each sample is the matrix's value rounded, within 0.51 (the
// 16-bit coefficients move a value by at most 0.01). Odd and even sizes,
// one-pixel rows and columns, 8- and 16-bit samples, padded strides.
TEST(VideoFrames, TenBitConversionMatchesTheMatrix) {
  const double k = 1023.0 / 255.0;
  expect_conversion<std::uint16_t>(
      [](const Image& img, std::uint16_t* y, std::uint16_t* u, std::uint16_t* v, int ys, int us, int vs) {
        rgb_to_i010(img, {y, u, v, ys, us, vs});
      },
      false, [k](double r, double g, double b) { return k * (0.299 * r + 0.587 * g + 0.114 * b); },
      [k](double r, double g, double b) {
        return std::clamp(512.0 + k * (-0.168736 * r - 0.331264 * g + 0.5 * b), 0.0, 1023.0);
      },
      [k](double r, double g, double b) {
        return std::clamp(512.0 + k * (0.5 * r - 0.418688 * g - 0.081312 * b), 0.0, 1023.0);
      },
      0.51);
}

// A 10-bit AV1 stream keeps to speeds 5 and 6 (libaom 3.6 crashes at 7 at 10
// bits); with a bound no frame meets it goes from 5 to 6 after 3 delta
// frames, and after 9 more (3 windows of 3 over the bound in a row) goes on
// at 8 bits and speed 7 from a key frame that the same decoder takes (a new
// sequence header), then on to 9 as an 8-bit stream does. Given time again it comes back to 6, not 5, and stays
// at 8 bits. Each frame reports its depth; every picture decodes close to
// its source (30 dB, as above).
TEST(VideoFrames, TenBitAv1FallsBackToEightBitsWhenTooSlow) {
  VideoEncoder enc({VideoCodec::kAv1, 64, 48, 500, 1, 5, 1e-6, 10});
  ASSERT_EQ(enc.settings().bit_depth, 10);
  VideoDecoder dec(VideoCodec::kAv1);
  std::vector<int> speeds, bits, keys;
  for (int t = 0; t < 26; ++t) {
    const Image src = moving_picture(64, 48, t);
    const EncodedVideoFrame f = enc.encode(src, 33.0 * t);
    speeds.push_back(f.speed);
    bits.push_back(f.bit_depth);
    if (f.key) keys.push_back(t);
    EXPECT_GT(compare_levels(dec.decode(f.data), src).psnr_db, 30.0) << "frame " << t;
  }
  EXPECT_EQ(speeds, (std::vector<int>{5, 5, 5, 5, 6, 6, 6, 6, 6, 6, 6, 6, 6, 7, 7, 7, 7, 8, 8, 8, 9,
                                      9, 9, 9, 9, 9}));
  EXPECT_EQ(bits, (std::vector<int>{10, 10, 10, 10, 10, 10, 10, 10, 10, 10, 10, 10, 10, 8, 8, 8, 8, 8,
                                    8, 8, 8, 8, 8, 8, 8, 8}));
  EXPECT_EQ(keys, (std::vector<int>{0, 13}));
  EXPECT_EQ(enc.settings().bit_depth, 8);
  enc.set_max_encode_ms(1e9);
  speeds.clear();
  for (int t = 26; t < 42; ++t) {
    const EncodedVideoFrame f = enc.encode(moving_picture(64, 48, t), 33.0 * t);
    speeds.push_back(f.speed);
    EXPECT_EQ(f.bit_depth, 8);
    EXPECT_FALSE(f.key);
  }
  // Frames 24 and 25 were already timed at 9: the third, frame 26, decides.
  EXPECT_EQ(speeds, (std::vector<int>{9, 8, 8, 8, 7, 7, 7, 6, 6, 6, 6, 6, 6, 6, 6, 6}));
}

// The server's depth: AV1 10 bits where it starts at speed 5 (up to 2^19
// pixels) on a machine of 4 cores or more, its shorter side under 1080; 8
// otherwise and for libvpx. An encoder is 8-bit unless told; a 10-bit one
// asked for speed 9 runs at 6, and VP9 cannot be 10-bit here.
TEST(VideoFrames, BitDepthFollowsCodecSizeAndCores) {
  EXPECT_EQ(video_encoder_bit_depth(VideoCodec::kAv1, 512, 512, 4), 10);
  EXPECT_EQ(video_encoder_bit_depth(VideoCodec::kAv1, 1024, 512, 16), 10);
  EXPECT_EQ(video_encoder_bit_depth(VideoCodec::kAv1, 512, 512, 2), 8);
  EXPECT_EQ(video_encoder_bit_depth(VideoCodec::kAv1, 1920, 1080, 16), 8);
  EXPECT_EQ(video_encoder_bit_depth(VideoCodec::kVp9, 512, 512, 16), 8);
  EXPECT_EQ(video_encoder_bit_depth(VideoCodec::kVp8, 512, 512, 16), 8);
  EXPECT_EQ(video_encoder_bit_depth(VideoCodec::kAv1, 1080, 240, 16), 10);
  EXPECT_TRUE(video_ten_bit_sound(1600, 900));
  EXPECT_FALSE(video_ten_bit_sound(1440, 1080));
  EXPECT_FALSE(video_ten_bit_sound(1080, 1920));
  EXPECT_TRUE(video_ten_bit_sound(400, 1080));
  EXPECT_EQ(VideoEncoder({VideoCodec::kAv1, 64, 48, 500, 1}).settings().bit_depth, 8);
  EXPECT_EQ(VideoEncoder({VideoCodec::kAv1, 64, 48, 500, 1, 0, 0.0, 10}).settings().bit_depth, 10);
  EXPECT_EQ(VideoEncoder({VideoCodec::kAv1, 64, 48, 500, 1, 9, 0.0, 10}).settings().speed, 6);
  EXPECT_THROW(VideoEncoder({VideoCodec::kVp9, 64, 48, 500, 1, 0, 0.0, 10}), InternalError);
  EXPECT_THROW(VideoEncoder({VideoCodec::kAv1, 64, 48, 500, 1, 0, 0.0, 12}), InternalError);
}

// The default speed: libvpx's 8; AV1 5 up to 2^19 pixels, 6 up to 1920x1080,
// 8 above. An encoder with speed 0 takes it, and one given a speed keeps it.
TEST(VideoFrames, DefaultSpeedFollowsCodecAndPictureSize) {
  EXPECT_EQ(video_encoder_speed(VideoCodec::kVp8, 1920, 1080), 8);
  EXPECT_EQ(video_encoder_speed(VideoCodec::kVp9, 512, 512), 8);
  EXPECT_EQ(video_encoder_speed(VideoCodec::kAv1, 512, 512), 5);
  EXPECT_EQ(video_encoder_speed(VideoCodec::kAv1, 1024, 512), 5);
  EXPECT_EQ(video_encoder_speed(VideoCodec::kAv1, 1280, 720), 6);
  EXPECT_EQ(video_encoder_speed(VideoCodec::kAv1, 1920, 1080), 6);
  EXPECT_EQ(video_encoder_speed(VideoCodec::kAv1, 2560, 1440), 8);
  EXPECT_EQ(VideoEncoder({VideoCodec::kAv1, 64, 48, 500, 1}).settings().speed, 5);
  EXPECT_EQ(VideoEncoder({VideoCodec::kAv1, 64, 48, 500, 1, 7}).settings().speed, 7);
  EXPECT_EQ(VideoEncoder({VideoCodec::kVp9, 64, 48, 500, 1}).settings().speed, 8);
  EXPECT_EQ(parse_video_codec("av1"), VideoCodec::kAv1);
  EXPECT_EQ(video_codec_name(VideoCodec::kAv1), "av1");
  EXPECT_FALSE(parse_video_codec("h264").has_value());
}

// Bands (libaom 3.6 runs a picture whose shorter side is 1080 or more at
// speed 7, kAv1FullSpeedRows): AV1 pictures over the row limit on their
// shorter side go as the fewest bands of at most that many rows, even rows
// but the last, which together cover the picture; VP8 and VP9 never. An
// encoder of one such picture says the speed libaom runs (7), a band's
// encoder the speed asked; 10 bits need bands there.
TEST(VideoFrames, BandsKeepAv1UnderTheRowsLibaomSlowsDownAt) {
  struct Case {
    VideoCodec codec;
    int width, height, max_rows, bands;
  };
  for (const Case& c : std::vector<Case>{{VideoCodec::kAv1, 1920, 1080, kAv1FullSpeedRows, 2},
                                         {VideoCodec::kAv1, 1080, 1080, kAv1FullSpeedRows, 2},
                                         {VideoCodec::kAv1, 1920, 1076, kAv1FullSpeedRows, 1},
                                         {VideoCodec::kAv1, 720, 1280, kAv1FullSpeedRows, 1},
                                         {VideoCodec::kAv1, 3840, 2160, kAv1FullSpeedRows, 3},
                                         {VideoCodec::kVp9, 1920, 1080, kAv1FullSpeedRows, 1},
                                         {VideoCodec::kAv1, 512, 512, 256, 2},
                                         {VideoCodec::kAv1, 512, 513, 256, 3}}) {
    EXPECT_EQ(video_encoder_bands(c.codec, c.width, c.height, c.max_rows), c.bands)
        << c.width << "x" << c.height << " at most " << c.max_rows << " rows";
  }
  for (const auto& [h, n] : std::vector<std::pair<int, int>>{{1080, 2}, {1081, 2}, {2160, 3}, {513, 3}, {7, 2}}) {
    int sum = 0;
    for (int i = 0; i < n; ++i) {
      const int rows = video_band_rows(h, n, i);
      EXPECT_GT(rows, 0) << h << " " << i;
      if (i + 1 < n) EXPECT_EQ(rows % 2, 0) << h << " " << i;
      sum += rows;
    }
    EXPECT_EQ(sum, h);
  }
  EXPECT_EQ(video_band_rows(1080, 2, 0), 540);
  EXPECT_EQ(video_band_rows(1081, 2, 1), 539);
  EXPECT_EQ(video_band_rows(2160, 3, 2), 720);
  EXPECT_LE(video_band_rows(7, 3, 2), 0);
  EXPECT_EQ(VideoEncoder({VideoCodec::kAv1, 1920, 1080, 1000, 1, 6}).settings().speed, 7);
  EXPECT_EQ(VideoEncoder({VideoCodec::kAv1, 1920, 1076, 1000, 1, 6}).settings().speed, 6);
  EXPECT_EQ(VideoEncoder({VideoCodec::kAv1, 1920, 1080, 1000, 2, 6, 0.0, 8, 2}).settings().speed, 6);
  EXPECT_TRUE(video_ten_bit_sound(1920, 1080, 2));
  EXPECT_EQ(VideoEncoder({VideoCodec::kAv1, 1920, 1080, 1000, 2, 6, 0.0, 10, 2}).settings().bit_depth, 10);
  EXPECT_THROW(VideoEncoder({VideoCodec::kAv1, 1920, 1080, 1000, 2, 6, 0.0, 10}), InternalError);
  EXPECT_THROW(VideoEncoder({VideoCodec::kVp9, 64, 48, 500, 1, 0, 0.0, 8, 2}), InternalError);
  EXPECT_THROW(VideoEncoder({VideoCodec::kAv1, 64, 2, 500, 1, 0, 0.0, 8, 3}), InternalError);
}

// A stream in 2 bands (as 1920x1080 goes, here at 128x96 to be quick) at 8
// and 10 bits: every frame is a key frame in every band or in none; packed
// with the band sizes after the header and unpacked, each band decodes with
// its own decoder and the stacked picture is within 30 dB of its source (as
// above; a band out of place or of the wrong height gives under 20 dB); the
// speed adapts in all bands together, and a 10-bit stream too slow falls
// back to 8 bits in all bands with one key frame.
TEST(VideoFrames, BandsDecodeToTheWholePicture) {
  for (int bits : {8, 10}) {
    VideoEncoder enc({VideoCodec::kAv1, 128, 96, 800, 2, 5, 1e-6, bits, 2});
    VideoDecoder dec(VideoCodec::kAv1), packed_dec(VideoCodec::kAv1);
    std::vector<int> keys, speeds, depths;
    for (int t = 0; t < 16; ++t) {
      const Image src = moving_picture(128, 96, t);
      const EncodedVideoFrame f = enc.encode(src, 33.0 * t, t == 3);
      ASSERT_EQ(f.band_bytes.size(), 2u);
      EXPECT_EQ(f.band_bytes[0] + f.band_bytes[1], f.data.size());
      if (f.key) keys.push_back(t);
      speeds.push_back(f.speed);
      depths.push_back(f.bit_depth);
      const std::vector<std::uint8_t> wire = pack_video_frame(f, VideoCodec::kAv1);
      EXPECT_EQ(wire[6], 2);
      const VideoFrameView v = unpack_video_frame(wire);
      ASSERT_EQ(v.bands.size(), 2u);
      EXPECT_EQ(v.bands[0].size(), f.band_bytes[0]);
      EXPECT_EQ(v.key, f.key);
      const Image shown = packed_dec.decode(std::span<const std::span<const std::uint8_t>>(v.bands));
      ASSERT_EQ(shown.height, 96);
      EXPECT_GT(compare_levels(shown, src).psnr_db, 30.0) << bits << " bits, frame " << t;
      EXPECT_EQ(compare_levels(dec.decode(f), shown).psnr_db, compare_levels(shown, shown).psnr_db);
    }
    if (bits == 8) {
      EXPECT_EQ(keys, (std::vector<int>{0, 3}));
      // Delta frames 1, 2 and 4 make the first window (key frames are not timed).
      EXPECT_EQ(speeds, (std::vector<int>{5, 5, 5, 5, 5, 6, 6, 6, 7, 7, 7, 8, 8, 8, 9, 9}));
    } else {
      // 6 from frame 5; frames 5-13 are 3 windows over the bound at 6; frame
      // 14 is the key frame at 8 bits and speed 7.
      EXPECT_EQ(keys, (std::vector<int>{0, 3, 14}));
      EXPECT_EQ(depths, (std::vector<int>{10, 10, 10, 10, 10, 10, 10, 10, 10, 10, 10, 10, 10, 10, 8, 8}));
      EXPECT_EQ(speeds[14], 7);
    }
  }
}

}  // namespace
}  // namespace beamcast
