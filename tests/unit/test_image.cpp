// Images: tone mapping, PNG round trips, error metrics.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "protocol/check.hpp"
#include "render/image.hpp"

namespace beamcast {
namespace {

HdrImage make_hdr(int w, int h, std::vector<float> rgb) {
  HdrImage img;
  img.width = w;
  img.height = h;
  img.rgb = std::move(rgb);
  return img;
}

Image make_image(int w, int h, int depth, std::vector<std::uint16_t> rgb) {
  Image img;
  img.width = w;
  img.height = h;
  img.bit_depth = depth;
  img.rgb = std::move(rgb);
  return img;
}

// Deterministic pseudo-random content covering the full level range.
Image pattern(int w, int h, int depth) {
  Image img = make_image(w, h, depth, {});
  img.rgb.resize(3 * static_cast<std::size_t>(w) * h);
  const std::uint32_t mask = depth == 16 ? 0xffff : 0xff;
  std::uint32_t state = 12345;
  for (auto& v : img.rgb) {
    state = state * 1664525u + 1013904223u;
    v = static_cast<std::uint16_t>((state >> 8) & mask);
  }
  img.rgb[0] = 0;
  img.rgb[1] = static_cast<std::uint16_t>(mask);
  return img;
}

TEST(ToneMap, KnownValues) {
  // E = 0 maps to level 0 for every curve; exposure scales E before the curve.
  for (ToneCurve curve : {ToneCurve::kExponential, ToneCurve::kReinhard, ToneCurve::kClamp}) {
    OutputSettings out;
    out.tone = curve;
    const Image img = tone_map(make_hdr(1, 1, {0.0f, 0.0f, 0.0f}), out);
    EXPECT_EQ(img.rgb[0], 0);
    EXPECT_EQ(img.rgb[2], 0);
  }
  // Exponential curve at x = 1: srgb_encode(1 - e^-1), rounded to the level.
  OutputSettings out;
  out.tone = ToneCurve::kExponential;
  for (int depth : {8, 16}) {
    out.bit_depth = depth;
    const double maxv = depth == 8 ? 255.0 : 65535.0;
    const long expected = std::lround(srgb_encode(1.0 - std::exp(-1.0)) * maxv);
    // Same value reached through exposure 2 and E = 0.5 (exact in float).
    out.exposure = 2.0;
    const Image img = tone_map(make_hdr(1, 1, {0.5f, 0.5f, 0.5f}), out);
    EXPECT_EQ(img.bit_depth, depth);
    EXPECT_EQ(img.rgb[0], expected);
    EXPECT_EQ(img.rgb[1], expected);
  }
  // Clamp saturates; Reinhard at 1 is 1/2.
  out.bit_depth = 8;
  out.exposure = 1.0;
  out.tone = ToneCurve::kClamp;
  EXPECT_EQ(tone_map(make_hdr(1, 1, {7.0f, 1.0f, 0.0f}), out).rgb[0], 255);
  out.tone = ToneCurve::kReinhard;
  EXPECT_EQ(tone_map(make_hdr(1, 1, {1.0f, 1.0f, 1.0f}), out).rgb[0],
            std::lround(srgb_encode(0.5) * 255.0));
  // Negative energy and NaN cannot produce garbage levels.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const Image bad = tone_map(make_hdr(1, 1, {-1.0f, nan, std::numeric_limits<float>::infinity()}), out);
  EXPECT_EQ(bad.rgb[0], 0);
  EXPECT_EQ(bad.rgb[1], 0);
  EXPECT_EQ(bad.rgb[2], 255);
}

TEST(ToneMap, SrgbEncode) {
  // The IEC 61966-2-1 curve: endpoints exact, linear segment below 0.0031308,
  // and the two pieces meet (continuity to ~1e-7 is the standard's own rounding
  // of its constants, so 1e-6 is a safe bound).
  EXPECT_EQ(srgb_encode(0.0), 0.0);
  EXPECT_NEAR(srgb_encode(1.0), 1.0, 1e-15);  // 1.055 - 0.055 in double
  EXPECT_DOUBLE_EQ(srgb_encode(0.001), 0.01292);
  EXPECT_NEAR(srgb_encode(0.0031308), srgb_encode(0.0031308 + 1e-12), 1e-6);
}

TEST(Png, RoundTrip8And16Bit) {
  for (int depth : {8, 16}) {
    const Image img = pattern(37, 23, depth);
    for (int level : {0, 3, 9}) {
      const auto bytes = encode_png(img, level);
      const Image back = decode_png(bytes);
      EXPECT_EQ(back.width, img.width);
      EXPECT_EQ(back.height, img.height);
      EXPECT_EQ(back.bit_depth, depth);
      EXPECT_EQ(back.rgb, img.rgb) << "depth " << depth << " level " << level;
    }
    // Explicit filter masks (0x08 = PNG_FILTER_NONE, 0xf8 = all).
    for (int filters : {0x08, 0xf8}) {
      EXPECT_EQ(decode_png(encode_png(img, 6, filters)).rgb, img.rgb);
    }
  }
}

TEST(Png, SixteenBitIsBigEndian) {
  // One pixel 0x1234: the IDAT is compressed, so check the decoded value and
  // that an 8-bit decode of the same value is impossible to confuse (0x12 vs 0x34).
  const Image img = make_image(1, 1, 16, {0x1234, 0x00ff, 0xff00});
  const Image back = decode_png(encode_png(img, 0));
  EXPECT_EQ(back.rgb[0], 0x1234);
  EXPECT_EQ(back.rgb[1], 0x00ff);
  EXPECT_EQ(back.rgb[2], 0xff00);
}

TEST(Png, FileRoundTripAndErrors) {
  const Image img = pattern(5, 4, 8);
  const auto file = std::filesystem::temp_directory_path() / "beamcast_test_image_roundtrip.png";
  write_png(file, img);
  EXPECT_EQ(read_png(file).rgb, img.rgb);
  std::filesystem::remove(file);
  EXPECT_THROW(decode_png({1, 2, 3}), std::runtime_error);
  auto bytes = encode_png(img);
  bytes.resize(bytes.size() / 2);  // truncated stream
  EXPECT_THROW(decode_png(bytes), std::runtime_error);
  EXPECT_THROW(read_png("/nonexistent/beamcast.png"), std::runtime_error);
}

TEST(Metrics, CompareHdr) {
  const HdrImage ref = make_hdr(2, 1, {1, 2, 3, 0, 0, 4});
  const HdrImage img = make_hdr(2, 1, {1, 2.5f, 3, 0, 1, 4});
  const HdrError e = compare_hdr(img, ref);
  // Differences 0, .5, 0, 0, 1, 0 (all exact in binary floating point).
  EXPECT_DOUBLE_EQ(e.max_abs, 1.0);
  EXPECT_DOUBLE_EQ(e.rms, std::sqrt(1.25 / 6.0));
  EXPECT_DOUBLE_EQ(e.rel_l1, 1.5 / 10.0);
  EXPECT_EQ(e.nonfinite, 0);
  const HdrError same = compare_hdr(ref, ref);
  EXPECT_EQ(same.max_abs, 0.0);
  EXPECT_EQ(same.rel_l1, 0.0);
  const HdrImage zero = make_hdr(1, 1, {0, 0, 0});
  EXPECT_EQ(compare_hdr(zero, zero).rel_l1, 0.0);  // both zero: defined as 0
}

TEST(Metrics, NonFiniteCountedNotPoisoning) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const HdrImage ref = make_hdr(2, 1, {1, 1, 1, 1, 1, 1});
  const HdrImage img = make_hdr(2, 1, {nan, 1, inf, 1, 3, -inf});
  const HdrError e = compare_hdr(img, ref);
  EXPECT_EQ(e.nonfinite, 3);
  // The finite values (1, 1, 3 against 1, 1, 1) alone make up the metrics.
  EXPECT_DOUBLE_EQ(e.max_abs, 2.0);
  EXPECT_DOUBLE_EQ(e.rms, std::sqrt(4.0 / 3.0));
  EXPECT_DOUBLE_EQ(e.rel_l1, 2.0 / 3.0);
  EXPECT_TRUE(std::isfinite(e.rms));
}

TEST(Metrics, CompareLevelsAndDiff) {
  const Image ref = make_image(2, 1, 8, {10, 20, 30, 40, 50, 60});
  const Image img = make_image(2, 1, 8, {10, 22, 30, 39, 50, 66});
  const LevelError e = compare_levels(img, ref, 1);
  EXPECT_EQ(e.max_abs, 6);
  EXPECT_DOUBLE_EQ(e.rms, std::sqrt((4.0 + 1.0 + 36.0) / 6.0));
  EXPECT_DOUBLE_EQ(e.psnr_db, 10.0 * std::log10(255.0 * 255.0 / ((4.0 + 1.0 + 36.0) / 6.0)));
  EXPECT_EQ(e.over, 2);  // 2 and 6 exceed 1; the 1 does not
  const LevelError same = compare_levels(ref, ref);
  EXPECT_TRUE(std::isinf(same.psnr_db));
  EXPECT_EQ(same.max_abs, 0);
  EXPECT_EQ(same.over, 0);

  const Image d = diff_image(img, ref);
  EXPECT_EQ(d.bit_depth, 8);
  // Amplified so that the largest difference (6) is white: 2 -> 85, 1 -> 43 (42.5 rounded).
  EXPECT_EQ(d.rgb, (std::vector<std::uint16_t>{0, 85, 0, 43, 0, 255}));
  EXPECT_EQ(diff_image(ref, ref).rgb, std::vector<std::uint16_t>(6, 0));

  const Image other = make_image(2, 1, 16, {10, 20, 30, 40, 50, 60});
  EXPECT_THROW(compare_levels(other, ref), InternalError);  // a caller's bug
}

}  // namespace
}  // namespace beamcast
