#include "render/video.hpp"

#include <aom/aom_decoder.h>
#include <aom/aom_encoder.h>
#include <aom/aomcx.h>
#include <aom/aomdx.h>
#include <vpx/vp8cx.h>
#include <vpx/vp8dx.h>
#include <vpx/vpx_decoder.h>
#include <vpx/vpx_encoder.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <future>
#include <stdexcept>
#include <string>

#include "protocol/check.hpp"

namespace beamcast {
namespace {

constexpr char kMagic[4] = {'B', 'C', 'V', '1'};

[[noreturn]] void aom_fail(aom_codec_ctx_t* ctx, const char* call) {
  std::string msg = std::string("libaom: ") + call + ": ";
  msg += ctx ? aom_codec_error(ctx) : "failed";
  if (ctx && aom_codec_error_detail(ctx)) msg += std::string(" (") + aom_codec_error_detail(ctx) + ")";
  throw std::runtime_error(msg);
}

[[noreturn]] void vpx_fail(vpx_codec_ctx_t* ctx, const char* call) {
  std::string msg = std::string("libvpx: ") + call + ": ";
  msg += ctx ? vpx_codec_error(ctx) : "failed";
  if (ctx && vpx_codec_error_detail(ctx)) msg += std::string(" (") + vpx_codec_error_detail(ctx) + ")";
  throw std::runtime_error(msg);
}

int clamp_byte(int v) { return std::clamp(v, 0, 255); }

// The BT.601 matrix in integers. Limited range (studio swing): the usual
// form with 8-bit coefficients. Full range (JPEG's YCbCr): 16-bit
// coefficients, 0.299 / 0.587 / 0.114 for Y, and U and V clamped to 0-255
// (pure blue or red rounds to 256).
struct LimitedRange {
  static unsigned char y(int r, int g, int b) {
    return static_cast<unsigned char>(((66 * r + 129 * g + 25 * b + 128) >> 8) + 16);
  }
  static unsigned char u(int r, int g, int b) {
    return static_cast<unsigned char>(((-38 * r - 74 * g + 112 * b + 128) >> 8) + 128);
  }
  static unsigned char v(int r, int g, int b) {
    return static_cast<unsigned char>(((112 * r - 94 * g - 18 * b + 128) >> 8) + 128);
  }
};
struct FullRange {
  static unsigned char y(int r, int g, int b) {
    return static_cast<unsigned char>((19595 * r + 38470 * g + 7471 * b + 32768) >> 16);
  }
  static unsigned char u(int r, int g, int b) {
    return static_cast<unsigned char>(
        clamp_byte(((-11059 * r - 21709 * g + 32768 * b + 32768) >> 16) + 128));
  }
  static unsigned char v(int r, int g, int b) {
    return static_cast<unsigned char>(
        clamp_byte(((32768 * r - 27439 * g - 5329 * b + 32768) >> 16) + 128));
  }
};

// Full-range BT.601 at 10 bits: the coefficients of FullRange scaled by
// 1023/255 (an 8-bit sample's share of the 10-bit scale), in 16 fractional
// bits. Y from one pixel; U and V from the sum of 4 pixels (two more
// fractional bits), centred on 512.
constexpr int coefficient10(double c) {
  const double x = c * 65536.0 * 1023.0 / 255.0;
  return static_cast<int>(x < 0 ? x - 0.5 : x + 0.5);
}
struct FullRange10 {
  static constexpr bool kFromSum = true;  // U and V from the 2x2 sum (u4, v4)
  static std::uint16_t y(int r, int g, int b) {
    constexpr int kr = coefficient10(0.299), kg = coefficient10(0.587), kb = coefficient10(0.114);
    return static_cast<std::uint16_t>((kr * r + kg * g + kb * b + (1 << 15)) >> 16);
  }
  // r, g, b: sums of 4 samples.
  static std::uint16_t u4(int r, int g, int b) {
    constexpr int kr = coefficient10(-0.168736), kg = coefficient10(-0.331264), kb = coefficient10(0.5);
    return static_cast<std::uint16_t>(std::clamp(((kr * r + kg * g + kb * b + (1 << 17)) >> 18) + 512, 0, 1023));
  }
  static std::uint16_t v4(int r, int g, int b) {
    constexpr int kr = coefficient10(0.5), kg = coefficient10(-0.418688), kb = coefficient10(-0.081312);
    return static_cast<std::uint16_t>(std::clamp(((kr * r + kg * g + kb * b + (1 << 17)) >> 18) + 512, 0, 1023));
  }
};

// One pass over row pairs: Y of both rows, then U and V of each 2x2 block
// from the sum of its pixels, where an odd last row or column counts its
// pixels twice (or four times), which is 4 times their mean. 8-bit ranges
// take the rounded mean, (sum + 2) >> 2, which is the rounded mean of the
// pixels there are; FullRange10 (kFromSum) the sum itself. Shift keeps the
// high byte of 16-bit samples. Written for speed (issue 42: at 1920x1080 the
// per-pixel form took ~15 ms of a frame's encode); the tests
// VideoFrames.*ConversionMatchesTheMatrix check it against the matrix pixel
// by pixel. Planes: I420Planes (8-bit samples) or I010Planes (16-bit).
template <class Range>
constexpr bool from_sum() {
  if constexpr (requires { Range::kFromSum; }) return Range::kFromSum;
  return false;
}

// Rows of an RGB image: `height` rows of `width` pixels from `rgb` (a band
// of a picture sent in bands is converted in place, not copied out).
struct RgbRows {
  const std::uint16_t* rgb;
  int width, height, bit_depth;
};

RgbRows rows_of(const Image& img, int first_row, int rows) {
  return {img.rgb.data() + 3 * static_cast<std::size_t>(img.width) * static_cast<std::size_t>(first_row),
          img.width, rows, img.bit_depth};
}

template <int Shift, class Range, class Planes>
void rgb_to_yuv420_rows(const RgbRows& src, const Planes& dst) {
  const int w = src.width, h = src.height;
  auto luma = [](const std::uint16_t* p) { return Range::y(p[0] >> Shift, p[1] >> Shift, p[2] >> Shift); };
  for (int y0 = 0; y0 < h; y0 += 2) {
    const bool two_rows = y0 + 1 < h;
    const std::uint16_t* r0 = src.rgb + 3 * static_cast<std::size_t>(y0) * w;
    const std::uint16_t* r1 = two_rows ? r0 + 3 * static_cast<std::size_t>(w) : r0;
    auto* y0p = dst.y + static_cast<std::size_t>(y0) * dst.y_stride;
    for (int x = 0; x < w; ++x) y0p[x] = luma(r0 + 3 * x);
    if (two_rows) {
      auto* y1p = y0p + dst.y_stride;
      for (int x = 0; x < w; ++x) y1p[x] = luma(r1 + 3 * x);
    }
    auto* u = dst.u + static_cast<std::size_t>(y0 / 2) * dst.u_stride;
    auto* v = dst.v + static_cast<std::size_t>(y0 / 2) * dst.v_stride;
    for (int cx = 0; cx < (w + 1) / 2; ++cx) {
      const std::uint16_t* p = r0 + 3 * (2 * cx);
      const std::uint16_t* q = r1 + 3 * (2 * cx);
      const int dx = 2 * cx + 1 < w ? 3 : 0;
      const int r = (p[0] >> Shift) + (p[dx] >> Shift) + (q[0] >> Shift) + (q[dx] >> Shift);
      const int g = (p[1] >> Shift) + (p[dx + 1] >> Shift) + (q[1] >> Shift) + (q[dx + 1] >> Shift);
      const int b = (p[2] >> Shift) + (p[dx + 2] >> Shift) + (q[2] >> Shift) + (q[dx + 2] >> Shift);
      if constexpr (from_sum<Range>()) {
        u[cx] = Range::u4(r, g, b);
        v[cx] = Range::v4(r, g, b);
      } else {
        const int rm = (r + 2) >> 2, gm = (g + 2) >> 2, bm = (b + 2) >> 2;
        u[cx] = Range::u(rm, gm, bm);
        v[cx] = Range::v(rm, gm, bm);
      }
    }
  }
}

// A decoded 4:2:0 picture, libvpx's or libaom's: 8-bit samples, or 16-bit
// ones holding `bits` (10).
struct I420View {
  const unsigned char* planes[3];
  int stride[3];  // bytes
  int w, h;
  ColorRange range = ColorRange::kLimited;
  int bits = 8;
};

// vpx_image_t and aom_image_t name their planes (Y, U, V: 0, 1, 2),
// strides, size and range alike (full range is 1 in both).
template <class CodecImage>
ColorRange color_range(const CodecImage& img) {
  static_assert(static_cast<int>(AOM_CR_FULL_RANGE) == 1 && static_cast<int>(VPX_CR_FULL_RANGE) == 1);
  return static_cast<int>(img.range) == 1 ? ColorRange::kFull : ColorRange::kLimited;
}

template <class CodecImage>
I420View i420_view(const CodecImage& img) {
  return {{img.planes[0], img.planes[1], img.planes[2]},
          {img.stride[0], img.stride[1], img.stride[2]},
          static_cast<int>(img.d_w),
          static_cast<int>(img.d_h),
          color_range(img),
          static_cast<int>(img.bit_depth)};
}

template <class CodecImage>
I420Planes i420_planes(CodecImage& img) {
  return {img.planes[0], img.planes[1], img.planes[2], img.stride[0], img.stride[1], img.stride[2]};
}

// libaom's 16-bit picture (AOM_IMG_FMT_I42016): strides in bytes, halved.
I010Planes i010_planes(aom_image_t& img) {
  auto plane = [&](int i) { return reinterpret_cast<std::uint16_t*>(img.planes[i]); };
  return {plane(0), plane(1), plane(2), img.stride[0] / 2, img.stride[1] / 2, img.stride[2] / 2};
}

// The settings every stream shares, in libvpx's or libaom's encoder config
// (same field names): pts in milliseconds of the caller's clock, every frame
// out as soon as it is in (no lag), a reliable transport (TCP/WebSocket: no
// error resilience), the bitrate target, no frame dropped (each request gets
// its picture), the quantizer range and the rate control's slack; a
// `buffer_ms` long rate-control buffer starting `initial_ms` full.
template <class Config>
void set_common_config(Config& cfg, const VideoEncoderSettings& settings, unsigned initial_ms,
                       unsigned optimal_ms, unsigned buffer_ms) {
  cfg.g_w = static_cast<unsigned>(settings.width);
  cfg.g_h = static_cast<unsigned>(settings.height);
  cfg.g_timebase = {1, 1000};
  cfg.g_threads = static_cast<unsigned>(std::max(1, settings.threads));
  cfg.g_lag_in_frames = 0;
  cfg.g_error_resilient = 0;
  cfg.rc_target_bitrate = static_cast<unsigned>(settings.bitrate_kbps);
  cfg.rc_dropframe_thresh = 0;
  cfg.rc_min_quantizer = 2;
  cfg.rc_max_quantizer = 56;
  cfg.rc_undershoot_pct = 50;
  cfg.rc_overshoot_pct = 50;
  cfg.rc_buf_initial_sz = initial_ms;
  cfg.rc_buf_optimal_sz = optimal_ms;
  cfg.rc_buf_sz = buffer_ms;
}

// The frame packets libvpx or libaom has for the frame just encoded, appended
// to `out` (both libraries' packets and iterators have the same layout).
template <auto GetCxData, auto FramePacket, auto KeyFlag, class Ctx>
void append_frame_packets(Ctx* ctx, EncodedVideoFrame* out) {
  const void* iter = nullptr;
  while (const auto* pkt = GetCxData(ctx, &iter)) {
    if (pkt->kind != FramePacket) continue;
    const auto* p = static_cast<const std::uint8_t*>(pkt->data.frame.buf);
    out->data.insert(out->data.end(), p, p + pkt->data.frame.sz);
    out->key = out->key || (pkt->data.frame.flags & KeyFlag) != 0;
  }
}

// The inverse, chroma upsampled bilinearly between sample centres (what a
// browser's video path does; nearest would add blockiness the stream lacks).
// Limited range in integers (what the VP8/VP9 rows of docs/performance.md
// were measured with); full range in floating point with one rounding at the
// end, as a browser's GPU converts.
Image i420_to_rgb(const I420View& src) {
  const int w = src.w, h = src.h;
  const int cw = (w + 1) / 2, ch = (h + 1) / 2;
  Image out;
  out.width = w;
  out.height = h;
  out.bit_depth = 8;
  out.rgb.resize(3 * static_cast<std::size_t>(w) * h);
  BEAMCAST_CHECK(src.bits == 8 || src.range == ColorRange::kFull, "a 10-bit picture is full range");
  auto sample = [&](int plane, int x, int y) -> double {
    const unsigned char* row = src.planes[plane] + static_cast<std::size_t>(y) * src.stride[plane];
    if (src.bits > 8) return reinterpret_cast<const std::uint16_t*>(row)[x];
    return row[x];
  };
  auto chroma = [&](int plane, double fx, double fy) {
    const int x0 = std::clamp(static_cast<int>(std::floor(fx)), 0, cw - 1);
    const int y0 = std::clamp(static_cast<int>(std::floor(fy)), 0, ch - 1);
    const int x1 = std::min(x0 + 1, cw - 1), y1 = std::min(y0 + 1, ch - 1);
    const double ax = std::clamp(fx - x0, 0.0, 1.0), ay = std::clamp(fy - y0, 0.0, 1.0);
    auto at = [&](int x, int y) { return sample(plane, x, y); };
    return (1 - ay) * ((1 - ax) * at(x0, y0) + ax * at(x1, y0)) +
           ay * ((1 - ax) * at(x0, y1) + ax * at(x1, y1));
  };
  // Full range: samples to the 8-bit scale (x 255/1023 at 10 bits), offset
  // 128 of it for U and V.
  const double to8 = src.bits > 8 ? 255.0 / ((1 << src.bits) - 1) : 1.0;
  const double mid = src.bits > 8 ? (1 << (src.bits - 1)) : 128.0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double fx = (x - 0.5) / 2.0, fy = (y - 0.5) / 2.0;
      if (src.range == ColorRange::kFull) {
        const double l = to8 * sample(0, x, y);
        const double cb = to8 * (chroma(1, fx, fy) - mid), cr = to8 * (chroma(2, fx, fy) - mid);
        std::uint16_t* o = &out.rgb[3 * (static_cast<std::size_t>(y) * w + x)];
        o[0] =
            static_cast<std::uint16_t>(clamp_byte(static_cast<int>(std::lround(l + 1.402 * cr))));
        o[1] = static_cast<std::uint16_t>(
            clamp_byte(static_cast<int>(std::lround(l - 0.344136 * cb - 0.714136 * cr))));
        o[2] =
            static_cast<std::uint16_t>(clamp_byte(static_cast<int>(std::lround(l + 1.772 * cb))));
        continue;
      }
      const int c = static_cast<int>(sample(0, x, y)) - 16;
      const int d = static_cast<int>(std::lround(chroma(1, fx, fy))) - 128;
      const int e = static_cast<int>(std::lround(chroma(2, fx, fy))) - 128;
      std::uint16_t* o = &out.rgb[3 * (static_cast<std::size_t>(y) * w + x)];
      o[0] = static_cast<std::uint16_t>(clamp_byte((298 * c + 409 * e + 128) >> 8));
      o[1] = static_cast<std::uint16_t>(clamp_byte((298 * c - 100 * d - 208 * e + 128) >> 8));
      o[2] = static_cast<std::uint16_t>(clamp_byte((298 * c + 516 * d + 128) >> 8));
    }
  }
  return out;
}

}  // namespace

namespace {

void to_i420(const RgbRows& src, const I420Planes& dst, ColorRange range) {
  const bool wide = src.bit_depth == 16;
  if (range == ColorRange::kFull) {
    wide ? rgb_to_yuv420_rows<8, FullRange>(src, dst) : rgb_to_yuv420_rows<0, FullRange>(src, dst);
  } else {
    wide ? rgb_to_yuv420_rows<8, LimitedRange>(src, dst) : rgb_to_yuv420_rows<0, LimitedRange>(src, dst);
  }
}

void to_i010(const RgbRows& src, const I010Planes& dst) {
  src.bit_depth == 16 ? rgb_to_yuv420_rows<8, FullRange10>(src, dst)
                       : rgb_to_yuv420_rows<0, FullRange10>(src, dst);
}

}  // namespace

void rgb_to_i420(const Image& src, const I420Planes& dst, ColorRange range) {
  to_i420(rows_of(src, 0, src.height), dst, range);
}

void rgb_to_i010(const Image& src, const I010Planes& dst) { to_i010(rows_of(src, 0, src.height), dst); }

int video_encoder_threads(int width, int height, int cores, int bit_depth) {
  const long long pixels = static_cast<long long>(std::max(0, width)) * std::max(0, height);
  const long long per_thread = bit_depth > 8 ? 1LL << 17 : 1LL << 19;
  const long long wanted = std::max(1LL, (pixels + per_thread - 1) / per_thread);
  return static_cast<int>(std::min<long long>(wanted, std::clamp(cores, 1, 4)));
}

int video_encoder_speed(VideoCodec codec, int width, int height) {
  if (codec != VideoCodec::kAv1) return 8;
  const long long pixels = static_cast<long long>(std::max(0, width)) * std::max(0, height);
  return pixels <= (1LL << 19) ? 5 : pixels <= (1LL << 21) ? 6 : 8;
}

namespace {

// A band's share of the stream's bitrate: its share of the rows.
int band_kbps(int kbps, int rows, int height) {
  return std::max(1, static_cast<int>(static_cast<long long>(kbps) * rows / height));
}

}  // namespace

int video_band_rows(int height, int bands, int index) {
  BEAMCAST_CHECK(bands >= 1 && index >= 0 && index < bands, "video_band_rows: no such band");
  if (bands == 1) return height;
  const int rows = ((height + bands - 1) / bands + 1) & ~1;
  return index + 1 < bands ? rows : height - rows * index;  // <= 0: too few rows for the bands
}

int video_encoder_bands(VideoCodec codec, int width, int height, int max_rows) {
  max_rows = std::max(2, max_rows);
  if (codec != VideoCodec::kAv1 || std::min(width, height) <= max_rows) return 1;
  for (int n = 2; n <= kMaxVideoBands; ++n) {
    if (video_band_rows(height, n, 0) <= max_rows && video_band_rows(height, n, n - 1) > 0) return n;
  }
  return kMaxVideoBands;
}

bool video_ten_bit_sound(int width, int height, int bands) {
  return std::min(width, video_band_rows(height, std::max(1, bands), 0)) <= kAv1FullSpeedRows;
}

int video_encoder_bit_depth(VideoCodec codec, int width, int height, int cores) {
  const bool ten = codec == VideoCodec::kAv1 && video_encoder_speed(codec, width, height) <= 5 &&
                   cores >= 4 && video_ten_bit_sound(width, height);
  return ten ? 10 : 8;
}

std::string_view video_codec_name(VideoCodec c) {
  switch (c) {
    case VideoCodec::kVp8: return "vp8";
    case VideoCodec::kVp9: return "vp9";
    case VideoCodec::kAv1: return "av1";
  }
  return "vp8";
}

std::optional<VideoCodec> parse_video_codec(std::string_view name) {
  if (name == "vp8") return VideoCodec::kVp8;
  if (name == "vp9") return VideoCodec::kVp9;
  if (name == "av1") return VideoCodec::kAv1;
  return std::nullopt;
}

// One encoder of either library; the VideoEncoder's settings say which.
struct VideoEncoder::Impl {
  vpx_codec_ctx_t ctx{};
  vpx_codec_enc_cfg_t cfg{};
  vpx_image_t* img = nullptr;
  aom_codec_ctx_t actx{};
  aom_codec_enc_cfg_t acfg{};
  aom_image_t* aimg = nullptr;
  bool open = false, aopen = false;
  void open_av1(const VideoEncoderSettings& settings, int speed);
  void close_av1() {
    if (aimg) aom_img_free(aimg);
    if (aopen) aom_codec_destroy(&actx);
    aimg = nullptr;
    aopen = false;
  }
  ~Impl() {
    if (img) vpx_img_free(img);
    if (open) vpx_codec_destroy(&ctx);
    close_av1();
  }
};

namespace {

// Tile columns (log2) for `threads` workers: at most 4 columns, each at least
// 256 pixels wide (VP9's minimum; AV1 gets the same split).
int log2_tile_columns(int threads, int width) {
  int log2_tiles = 0;
  while (log2_tiles < 2 && (2 << log2_tiles) <= threads && (256 << (log2_tiles + 1)) <= width) {
    ++log2_tiles;
  }
  return log2_tiles;
}

// libaom's speed (cpu-used) and, from speed 6 on, no re-estimation of the
// coefficient, mode and motion-vector costs within a frame: on the bench's
// demo drag, together with the golden-frame boost, 7-17% less encode time
// at speed 6 (old and new alternated; at 7 no consistent difference) and
// fewer bytes at 7, within 3% at 6; at speed 5 it cost the demo 3-5% more
// bytes, so there the costs follow libaom's default (per superblock).
void set_av1_speed(aom_codec_ctx_t* c, int speed) {
  const int cost_updates = speed >= 6 ? 3 : 0;  // 3: off, 0: every superblock
  const bool ok = aom_codec_control(c, AOME_SET_CPUUSED, speed) == AOM_CODEC_OK &&
                  aom_codec_control(c, AV1E_SET_COEFF_COST_UPD_FREQ, cost_updates) == AOM_CODEC_OK &&
                  aom_codec_control(c, AV1E_SET_MODE_COST_UPD_FREQ, cost_updates) == AOM_CODEC_OK &&
                  aom_codec_control(c, AV1E_SET_MV_COST_UPD_FREQ, cost_updates) == AOM_CODEC_OK;
  if (!ok) aom_fail(c, "codec_control (speed)");
}

}  // namespace

// The quantizer range (0-63) of AV1 and VP9 streams: the CBR rate control
// of libaom and of libvpx's VP9 starts its average quantizer at the worst
// one allowed (av1_primary_rc_init, vp9_rc_init), so a stream that allowed
// 56 from the start spent its first second climbing down from ~40 at most
// 1/8 a frame, at a fraction of its bitrate (AV1, the demo drag at 1 000
// kbit/s: 600-900 bytes a frame for 10 frames after the key frame, 4 000
// once settled). Opening the encoder with 24 as the worst and widening to
// 56 before the first frame starts that average at 24 and leaves the key
// frame's quantizer free (a low bitrate's key frame is not held to 24);
// from there it rises as fast as a scene needs (20 quantizer-index steps a
// frame). Starting at 8, 16 or 24 gave the same bytes at equal PSNR on the
// demo drag (docs/performance.md, "The rate control's start and the colour
// range").
constexpr unsigned kStartMaxQuantizer = 24;
constexpr unsigned kMaxQuantizer = 56;

// The fastest speed a 10-bit AV1 stream runs at. libaom 3.6's realtime
// speeds from 7 on take the non-RD mode search, which at 10 bits crashed (7)
// or lost 4-5 dB at equal bytes (8, 9) on the demo drag; 5 and 6 are sound.
// A 10-bit stream that is too slow at 6 goes on at 8 bits (adapt_speed).
constexpr int kFastest10Bit = 6;
constexpr int kSlowWindows10Bit = 3;

// AV1 (libaom, realtime usage): one pass, no lag, CBR, no dropped frames,
// key frames at the start and on request only. Unlike the libvpx streams the
// key frame is not capped and the rate control's buffer is libaom's default
// (6 s, starting at 4): the drag's quality follows its first frame (together
// 0.6 dB at equal bytes on the demo drag); no adaptive quantization (cyclic
// refresh cost 0.1-0.4 dB). Tools that cost time and did not pay on that
// drag are off, as in libaom's own realtime example: the temporal dependency
// model, global and warped motion, OBMC, order hints (on: 0.2-0.4 dB better,
// 50% more time). A golden frame gets twice a frame's share of the bits
// (the camera moves: later frames predict from it). docs/performance.md,
// "Video preview: AV1" and "AV1 at the speeds a small machine runs".
void VideoEncoder::Impl::open_av1(const VideoEncoderSettings& settings, int speed) {
  Impl& impl = *this;
  aom_codec_iface_t* iface = aom_codec_av1_cx();
  aom_codec_enc_cfg_t& cfg = impl.acfg;
  if (aom_codec_enc_config_default(iface, &cfg, AOM_USAGE_REALTIME) != AOM_CODEC_OK) {
    aom_fail(nullptr, "config_default");
  }
  const int threads = std::max(1, settings.threads);
  set_common_config(cfg, settings, 4000, 5000, 6000);
  cfg.rc_max_quantizer = kStartMaxQuantizer;
  cfg.g_pass = AOM_RC_ONE_PASS;
  cfg.rc_end_usage = AOM_CBR;
  cfg.kf_mode = AOM_KF_DISABLED;
  const bool ten_bit = settings.bit_depth == 10;
  cfg.g_bit_depth = ten_bit ? AOM_BITS_10 : AOM_BITS_8;
  cfg.g_input_bit_depth = ten_bit ? 10 : 8;
  if (aom_codec_enc_init(&impl.actx, iface, &cfg, ten_bit ? AOM_CODEC_USE_HIGHBITDEPTH : 0) != AOM_CODEC_OK) {
    aom_fail(&impl.actx, "enc_init");
  }
  impl.aopen = true;
  aom_codec_ctx_t* c = &impl.actx;
  const bool ok =
      aom_codec_control(c, AV1E_SET_ROW_MT, 1) == AOM_CODEC_OK &&
      aom_codec_control(c, AV1E_SET_TILE_COLUMNS, log2_tile_columns(threads, settings.width)) ==
          AOM_CODEC_OK &&
      aom_codec_control(c, AV1E_SET_AQ_MODE, 0) == AOM_CODEC_OK &&
      aom_codec_control(c, AOME_SET_MAX_INTRA_BITRATE_PCT, 0) == AOM_CODEC_OK &&
      aom_codec_control(c, AV1E_SET_ENABLE_TPL_MODEL, 0) == AOM_CODEC_OK &&
      aom_codec_control(c, AV1E_SET_ENABLE_GLOBAL_MOTION, 0) == AOM_CODEC_OK &&
      aom_codec_control(c, AV1E_SET_ENABLE_WARPED_MOTION, 0) == AOM_CODEC_OK &&
      aom_codec_control(c, AV1E_SET_ENABLE_OBMC, 0) == AOM_CODEC_OK &&
      aom_codec_control(c, AV1E_SET_ENABLE_ORDER_HINT, 0) == AOM_CODEC_OK &&
      aom_codec_control(c, AV1E_SET_GF_CBR_BOOST_PCT, 100) == AOM_CODEC_OK &&
      // Full-range BT.601 YUV of sRGB pixels, said in the sequence
      // header: WebCodecs hands the browser a VideoFrame with this
      // colour space and the canvas converts back with it.
      aom_codec_control(c, AV1E_SET_COLOR_RANGE, AOM_CR_FULL_RANGE) == AOM_CODEC_OK &&
      aom_codec_control(c, AV1E_SET_MATRIX_COEFFICIENTS, AOM_CICP_MC_BT_601) == AOM_CODEC_OK &&
      aom_codec_control(c, AV1E_SET_COLOR_PRIMARIES, AOM_CICP_CP_BT_709) == AOM_CODEC_OK &&
      aom_codec_control(c, AV1E_SET_TRANSFER_CHARACTERISTICS, AOM_CICP_TC_SRGB) == AOM_CODEC_OK;
  if (!ok) aom_fail(c, "codec_control");
  set_av1_speed(c, speed);
  cfg.rc_max_quantizer = kMaxQuantizer;  // the rate control's average starts at the start cap
  if (aom_codec_enc_config_set(c, &cfg) != AOM_CODEC_OK) aom_fail(c, "enc_config_set (quantizer range)");
  impl.aimg = aom_img_alloc(nullptr, ten_bit ? AOM_IMG_FMT_I42016 : AOM_IMG_FMT_I420, cfg.g_w, cfg.g_h, 16);
  if (!impl.aimg) throw std::runtime_error("libaom: aom_img_alloc failed");
  impl.aimg->bit_depth = ten_bit ? 10 : 8;
  impl.aimg->range = AOM_CR_FULL_RANGE;
  impl.aimg->mc = AOM_CICP_MC_BT_601;
  impl.aimg->cp = AOM_CICP_CP_BT_709;
  impl.aimg->tc = AOM_CICP_TC_SRGB;
}

VideoEncoder::VideoEncoder(const VideoEncoderSettings& settings)
    : impl_(std::make_unique<Impl>()), settings_(settings) {
  BEAMCAST_CHECK(settings.width > 0 && settings.height > 0, "VideoEncoder: empty frame size");
  if (settings_.speed <= 0) settings_.speed = video_encoder_speed(settings.codec, settings.width, settings.height);
  BEAMCAST_CHECK(settings_.bands >= 1 && settings_.bands <= kMaxVideoBands &&
                     (settings_.bands == 1 || settings.codec == VideoCodec::kAv1) &&
                     video_band_rows(settings.height, settings_.bands, settings_.bands - 1) > 0,
                 "VideoEncoder: bands are for AV1, at most 16, each of at least one row");
  if (settings.codec == VideoCodec::kAv1) {
    BEAMCAST_CHECK(settings_.bit_depth == 8 || settings_.bit_depth == 10, "VideoEncoder: AV1 is 8- or 10-bit");
    BEAMCAST_CHECK(settings_.bit_depth == 8 || video_ten_bit_sound(settings.width, settings.height, settings_.bands),
                   "VideoEncoder: 10-bit AV1 with a shorter side of 1080 or more needs bands");
    settings_.speed = std::clamp(settings_.speed, 5, settings_.bit_depth == 10 ? kFastest10Bit : 9);
    const int band0 = video_band_rows(settings.height, settings_.bands, 0);
    // What libaom will run (kAv1FullSpeedRows), so that the frames say it
    // and the adaptation starts from it.
    if (std::min(settings.width, band0) > kAv1FullSpeedRows) settings_.speed = std::max(settings_.speed, 7);
    base_speed_ = settings_.speed;
    if (settings_.bands == 1) {
      impl_->open_av1(settings_, settings_.speed);
      return;
    }
    const int threads = std::max(1, settings.threads / settings_.bands);
    for (int i = 0; i < settings_.bands; ++i) {
      VideoEncoderSettings band = settings_;
      band.height = video_band_rows(settings.height, settings_.bands, i);
      band.bitrate_kbps = band_kbps(settings.bitrate_kbps, band.height, settings.height);
      band.threads = threads;
      band.max_encode_ms = 0.0;  // this encoder adapts the speed of all bands
      band.bands = 1;
      bands_.push_back(std::make_unique<VideoEncoder>(band));
    }
    return;
  }
  BEAMCAST_CHECK(settings_.bit_depth == 8, "VideoEncoder: VP8 and VP9 are 8-bit");
  const bool vp9 = settings.codec == VideoCodec::kVp9;
  vpx_codec_iface_t* iface = vp9 ? vpx_codec_vp9_cx() : vpx_codec_vp8_cx();
  vpx_codec_enc_cfg_t& cfg = impl_->cfg;
  if (vpx_codec_enc_config_default(iface, &cfg, 0) != VPX_CODEC_OK) vpx_fail(nullptr, "config_default");
  set_common_config(cfg, settings, 500, 600, 1000);
  cfg.g_pass = VPX_RC_ONE_PASS;
  cfg.rc_end_usage = VPX_CBR;
  cfg.kf_mode = VPX_KF_DISABLED;  // key frames at the start and on request only
  if (vp9) cfg.rc_max_quantizer = kStartMaxQuantizer;
  if (vpx_codec_enc_init(&impl_->ctx, iface, &cfg, 0) != VPX_CODEC_OK) vpx_fail(&impl_->ctx, "enc_init");
  impl_->open = true;
  impl_->img = vpx_img_alloc(nullptr, VPX_IMG_FMT_I420, cfg.g_w, cfg.g_h, 16);
  if (!impl_->img) throw std::runtime_error("libvpx: vpx_img_alloc failed");
  vpx_codec_ctx_t* c = &impl_->ctx;
  // Realtime speed settings (libvpx's own realtime examples use these
  // ranges): VP8 -cpu-used 8 (of 16), VP9 speed 8 (of 9), no alt-ref frames,
  // key frames capped at 3x a frame's share of the bitrate. With threads,
  // VP9 splits the picture into tile columns (at least 256 pixels wide each)
  // and rows (row-mt); VP8 threads over macroblock rows and writes as many
  // token partitions so that a decoder may too.
  settings_.speed = std::clamp(settings_.speed, vp9 ? 5 : 4, vp9 ? 9 : 16);
  base_speed_ = settings_.speed;
  const int speed = settings_.speed;
  const int threads = std::max(1, settings.threads);
  if (vp9) {
    vpx_codec_control(c, VP8E_SET_CPUUSED, speed);
    vpx_codec_control(c, VP9E_SET_ROW_MT, 1);
    vpx_codec_control(c, VP9E_SET_AQ_MODE, 3);
    vpx_codec_control(c, VP9E_SET_TILE_COLUMNS, std::max(1, log2_tile_columns(threads, settings.width)));
    // Full-range BT.601, said in the frame headers, as for AV1 (VP8 has no
    // way to say it and stays limited range).
    if (vpx_codec_control(c, VP9E_SET_COLOR_SPACE, VPX_CS_BT_601) != VPX_CODEC_OK ||
        vpx_codec_control(c, VP9E_SET_COLOR_RANGE, VPX_CR_FULL_RANGE) != VPX_CODEC_OK) {
      vpx_fail(c, "codec_control (colour)");
    }
    impl_->img->cs = VPX_CS_BT_601;
    impl_->img->range = VPX_CR_FULL_RANGE;
    cfg.rc_max_quantizer = kMaxQuantizer;  // the rate control's average starts at the start cap
    if (vpx_codec_enc_config_set(c, &cfg) != VPX_CODEC_OK) vpx_fail(c, "enc_config_set (quantizer range)");
  } else {
    int log2_parts = 0;
    while (log2_parts < 3 && (2 << log2_parts) <= threads) ++log2_parts;
    vpx_codec_control(c, VP8E_SET_CPUUSED, speed);
    vpx_codec_control(c, VP8E_SET_NOISE_SENSITIVITY, 0);
    vpx_codec_control(c, VP8E_SET_STATIC_THRESHOLD, 1);
    vpx_codec_control(c, VP8E_SET_TOKEN_PARTITIONS, log2_parts);
  }
  vpx_codec_control(c, VP8E_SET_ENABLEAUTOALTREF, 0);
  vpx_codec_control(c, VP8E_SET_MAX_INTRA_BITRATE_PCT, 300);
}

VideoEncoder::~VideoEncoder() = default;

void VideoEncoder::set_bitrate(int kbps) {
  if (kbps == settings_.bitrate_kbps) return;
  for (auto& band : bands_) {
    band->set_bitrate(band_kbps(kbps, band->settings_.height, settings_.height));
  }
  if (!bands_.empty()) {
    settings_.bitrate_kbps = kbps;
    return;
  }
  if (settings_.codec == VideoCodec::kAv1) {
    impl_->acfg.rc_target_bitrate = static_cast<unsigned>(kbps);
    if (aom_codec_enc_config_set(&impl_->actx, &impl_->acfg) != AOM_CODEC_OK) {
      aom_fail(&impl_->actx, "enc_config_set");
    }
  } else {
    impl_->cfg.rc_target_bitrate = static_cast<unsigned>(kbps);
    if (vpx_codec_enc_config_set(&impl_->ctx, &impl_->cfg) != VPX_CODEC_OK) {
      vpx_fail(&impl_->ctx, "enc_config_set");
    }
  }
  settings_.bitrate_kbps = kbps;
}

void VideoEncoder::adapt_speed(double encode_ms) {
  constexpr std::size_t kWindow = 3;
  constexpr int kFastest = 9;
  recent_.push_back(encode_ms);
  if (recent_.size() > kWindow) recent_.erase(recent_.begin());
  if (recent_.size() < kWindow) return;
  double mean = 0.0;
  for (double ms : recent_) mean += ms;
  mean /= kWindow;
  int next = settings_.speed;
  const bool ten_bit = settings_.bit_depth == 10;
  if (mean > settings_.max_encode_ms && next < kFastest) ++next;
  if (mean < 0.5 * settings_.max_encode_ms && next > base_speed_) --next;
  if (ten_bit && next > kFastest10Bit) {
    // Too slow at 10 bits' fastest for 3 windows in a row (9 delta frames,
    // 0.3 s at 30 frames/s: not for a moment's load on the machine, which
    // the browser test's first frames see): the stream goes on at 8 bits and
    // the next speed, from a key frame (a new sequence header; it costs about
    // five frames' bytes), and stays at 8 bits until the encoder is made
    // again (a new size or codec).
    recent_.clear();
    if (++slow_windows_ < kSlowWindows10Bit) return;
    reopen_av1_8bit(next);
    key_next_ = true;
    return;
  }
  slow_windows_ = 0;
  if (next == settings_.speed) return;
  set_av1_speed_all(next);
  recent_.clear();
}

void VideoEncoder::set_av1_speed_all(int speed) {
  settings_.speed = speed;
  if (bands_.empty()) set_av1_speed(&impl_->actx, speed);
  for (auto& band : bands_) band->set_av1_speed_all(speed);
}

void VideoEncoder::reopen_av1_8bit(int speed) {
  settings_.bit_depth = 8;
  settings_.speed = speed;
  base_speed_ = std::max(base_speed_, kFastest10Bit);
  if (bands_.empty()) {
    impl_->close_av1();
    impl_->open_av1(settings_, speed);
  }
  for (auto& band : bands_) band->reopen_av1_8bit(speed);
}

// Each band encoded by its own encoder from its rows of `img` (converted in
// place), bands 1.. on threads of their own beside band 0 on this one; every
// band is a key frame when one is.
EncodedVideoFrame VideoEncoder::encode_bands(const Image& img, bool key, double time_ms) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t n = bands_.size();
  std::vector<int> first_rows(n, 0);
  for (std::size_t i = 1; i < n; ++i) first_rows[i] = first_rows[i - 1] + bands_[i - 1]->settings_.height;
  std::vector<std::future<EncodedVideoFrame>> others;
  for (std::size_t i = 1; i < n; ++i) {
    others.push_back(std::async(std::launch::async, [this, &img, &first_rows, i, key, time_ms] {
      return bands_[i]->encode_rows(img, first_rows[i], time_ms, key);
    }));
  }
  std::vector<EncodedVideoFrame> frames;
  frames.push_back(bands_[0]->encode_rows(img, 0, time_ms, key));
  for (auto& f : others) frames.push_back(f.get());
  EncodedVideoFrame out;
  out.key = key;
  for (const EncodedVideoFrame& f : frames) {
    BEAMCAST_CHECK(f.key == key, "a band's frame is not of the frame's type");
    out.data.insert(out.data.end(), f.data.begin(), f.data.end());
    out.band_bytes.push_back(f.data.size());
    out.quantizer = std::max(out.quantizer, f.quantizer);
  }
  out.encode_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

EncodedVideoFrame VideoEncoder::encode(const Image& img, double time_ms, bool force_key) {
  BEAMCAST_CHECK(img.width == settings_.width && img.height == settings_.height,
                 "VideoEncoder::encode: frame size differs from the encoder's");
  return encode_rows(img, 0, time_ms, force_key);
}

// The encoder's picture from rows first_row.. of `img` (a band's encoder
// reads its band of the whole picture; other encoders start at row 0).
EncodedVideoFrame VideoEncoder::encode_rows(const Image& img, int first_row, double time_ms, bool force_key) {
  BEAMCAST_CHECK(img.width == settings_.width && first_row >= 0 && first_row + settings_.height <= img.height,
                 "VideoEncoder::encode: the band is outside the frame");
  const bool av1 = settings_.codec == VideoCodec::kAv1;
  if (!bands_.empty()) {
    const bool key = force_key || frames_ == 0 || key_next_;
    key_next_ = false;
    EncodedVideoFrame out = encode_bands(img, key, time_ms);
    out.pts = frames_++;
    out.speed = settings_.speed;
    out.bit_depth = settings_.bit_depth;
    if (settings_.max_encode_ms > 0.0 && !out.key) adapt_speed(out.encode_ms);
    return out;
  }
  const auto t0 = std::chrono::steady_clock::now();
  BEAMCAST_CHECK(!av1 || impl_->aopen, "VideoEncoder: the AV1 encoder failed to reopen at 8 bits");
  // The encoder's picture says its range (set where the encoder opened).
  const RgbRows rows = rows_of(img, first_row, settings_.height);
  if (av1 && settings_.bit_depth == 10) {
    to_i010(rows, i010_planes(*impl_->aimg));
  } else if (av1) {
    to_i420(rows, i420_planes(*impl_->aimg), color_range(*impl_->aimg));
  } else {
    to_i420(rows, i420_planes(*impl_->img), color_range(*impl_->img));
  }
  // The frame lasts until the next one; the first gets a 30 frames/s share.
  const double gap = frames_ == 0 ? 33.0 : time_ms - last_ms_;
  const auto duration = static_cast<unsigned long>(std::clamp(std::lround(gap), 1L, 1000L));
  last_ms_ = time_ms;
  const bool key = force_key || frames_ == 0 || key_next_;
  key_next_ = false;
  EncodedVideoFrame out;
  if (av1) {
    if (aom_codec_encode(&impl_->actx, impl_->aimg, pts_ms_, duration,
                         key ? AOM_EFLAG_FORCE_KF : 0) != AOM_CODEC_OK) {
      aom_fail(&impl_->actx, "encode");
    }
    append_frame_packets<aom_codec_get_cx_data, AOM_CODEC_CX_FRAME_PKT, AOM_FRAME_IS_KEY>(
        &impl_->actx, &out);
    if (aom_codec_control(&impl_->actx, AOME_GET_LAST_QUANTIZER_64, &out.quantizer) !=
        AOM_CODEC_OK) {
      aom_fail(&impl_->actx, "codec_control (last quantizer)");
    }
  } else {
    if (vpx_codec_encode(&impl_->ctx, impl_->img, pts_ms_, duration, key ? VPX_EFLAG_FORCE_KF : 0,
                         VPX_DL_REALTIME) != VPX_CODEC_OK) {
      vpx_fail(&impl_->ctx, "encode");
    }
    append_frame_packets<vpx_codec_get_cx_data, VPX_CODEC_CX_FRAME_PKT, VPX_FRAME_IS_KEY>(&impl_->ctx, &out);
    if (vpx_codec_control(&impl_->ctx, VP8E_GET_LAST_QUANTIZER_64, &out.quantizer) != VPX_CODEC_OK) {
      vpx_fail(&impl_->ctx, "codec_control (last quantizer)");
    }
  }
  pts_ms_ += static_cast<std::int64_t>(duration);
  out.pts = frames_++;
  BEAMCAST_CHECK(!out.data.empty(), "the encoder gave no packet for a frame (lag 0, no frame dropping)");
  out.speed = settings_.speed;
  out.bit_depth = settings_.bit_depth;
  out.encode_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (av1 && settings_.max_encode_ms > 0.0 && !out.key) adapt_speed(out.encode_ms);
  return out;
}

struct VideoDecoder::Impl {
  VideoCodec codec = VideoCodec::kVp8;
  vpx_codec_ctx_t ctx{};
  aom_codec_ctx_t actx{};
  bool open = false, aopen = false;
  ~Impl() {
    if (open) vpx_codec_destroy(&ctx);
    if (aopen) aom_codec_destroy(&actx);
  }
};

VideoDecoder::VideoDecoder(VideoCodec codec) : impl_(std::make_unique<Impl>()) {
  impl_->codec = codec;
  if (codec == VideoCodec::kAv1) {
    aom_codec_dec_cfg_t cfg{};
    cfg.threads = 1;
    cfg.allow_lowbitdepth = 1;  // 8-bit pictures of an 8-bit stream (16-bit ones of a 10-bit stream)
    if (aom_codec_dec_init(&impl_->actx, aom_codec_av1_dx(), &cfg, 0) != AOM_CODEC_OK) {
      aom_fail(&impl_->actx, "dec_init");
    }
    impl_->aopen = true;
    return;
  }
  vpx_codec_iface_t* iface = codec == VideoCodec::kVp9 ? vpx_codec_vp9_dx() : vpx_codec_vp8_dx();
  vpx_codec_dec_cfg_t cfg{};
  cfg.threads = 1;
  if (vpx_codec_dec_init(&impl_->ctx, iface, &cfg, 0) != VPX_CODEC_OK) vpx_fail(&impl_->ctx, "dec_init");
  impl_->open = true;
}

VideoDecoder::~VideoDecoder() = default;

Image VideoDecoder::decode(std::span<const std::uint8_t> frame) {
  if (impl_->codec == VideoCodec::kAv1) {
    if (aom_codec_decode(&impl_->actx, frame.data(), frame.size(), nullptr) != AOM_CODEC_OK) {
      aom_fail(&impl_->actx, "decode");
    }
    aom_codec_iter_t iter = nullptr;
    const aom_image_t* img = aom_codec_get_frame(&impl_->actx, &iter);
    if (!img) throw std::runtime_error("libaom: decode: no picture");
    const bool ok = img->fmt == AOM_IMG_FMT_I420 ||
                    (img->fmt == AOM_IMG_FMT_I42016 && img->bit_depth == 10 && img->range == AOM_CR_FULL_RANGE);
    if (!ok) throw std::runtime_error("libaom: decode: not 8-bit I420 or full-range 10-bit I420");
    return i420_to_rgb(i420_view(*img));
  }
  if (vpx_codec_decode(&impl_->ctx, frame.data(), static_cast<unsigned>(frame.size()), nullptr, 0) !=
      VPX_CODEC_OK) {
    vpx_fail(&impl_->ctx, "decode");
  }
  vpx_codec_iter_t iter = nullptr;
  const vpx_image_t* img = vpx_codec_get_frame(&impl_->ctx, &iter);
  if (!img) throw std::runtime_error("libvpx: decode: no picture");
  if (img->fmt != VPX_IMG_FMT_I420) throw std::runtime_error("libvpx: decode: not I420");
  return i420_to_rgb(i420_view(*img));
}

Image VideoDecoder::decode(std::span<const std::span<const std::uint8_t>> bands) {
  if (bands.size() == 1) return decode(bands[0]);
  if (bands_.size() != bands.size()) {
    bands_.clear();
    for (std::size_t i = 0; i < bands.size(); ++i) bands_.push_back(std::make_unique<VideoDecoder>(impl_->codec));
  }
  Image out;
  for (std::size_t i = 0; i < bands.size(); ++i) {
    const Image part = bands_[i]->decode(bands[i]);
    if (i == 0) {
      out.width = part.width;
      out.bit_depth = part.bit_depth;
    } else if (part.width != out.width) {
      throw std::runtime_error("video: bands of different widths");
    }
    out.height += part.height;
    out.rgb.insert(out.rgb.end(), part.rgb.begin(), part.rgb.end());
  }
  return out;
}

Image VideoDecoder::decode(const EncodedVideoFrame& frame) {
  if (frame.band_bytes.empty()) return decode(std::span<const std::uint8_t>(frame.data));
  std::vector<std::span<const std::uint8_t>> parts;
  std::size_t offset = 0;
  for (std::size_t bytes : frame.band_bytes) {
    parts.push_back(std::span<const std::uint8_t>(frame.data).subspan(offset, bytes));
    offset += bytes;
  }
  return decode(std::span<const std::span<const std::uint8_t>>(parts));
}

static_assert(static_cast<int>(VideoCodec::kVp8) == 0 && static_cast<int>(VideoCodec::kVp9) == 1 &&
                  static_cast<int>(VideoCodec::kAv1) == 2,
              "the BCV1 header's codec byte is the enum's value");

namespace {

void put_u32(std::uint8_t* at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) at[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

std::uint32_t get_u32(const std::uint8_t* at) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(at[i]) << (8 * i);
  return v;
}

}  // namespace

std::vector<std::uint8_t> pack_video_frame(const EncodedVideoFrame& f, VideoCodec codec) {
  const std::size_t bands = f.band_bytes.size();
  BEAMCAST_CHECK(bands != 1 && bands <= static_cast<std::size_t>(kMaxVideoBands), "pack_video_frame: 2-16 bands");
  const std::size_t table = 4 * bands;
  std::vector<std::uint8_t> out(kVideoHeaderBytes + table + f.data.size());
  std::memcpy(out.data(), kMagic, 4);
  out[4] = f.key ? 1 : 0;
  out[5] = static_cast<std::uint8_t>(codec);  // 0 vp8, 1 vp9, 2 av1 (the enum's order)
  out[6] = static_cast<std::uint8_t>(bands);  // 0: one picture
  put_u32(out.data() + 8, static_cast<std::uint32_t>(f.pts));
  for (std::size_t i = 0; i < bands; ++i) {
    put_u32(out.data() + kVideoHeaderBytes + 4 * i, static_cast<std::uint32_t>(f.band_bytes[i]));
  }
  std::copy(f.data.begin(), f.data.end(), out.begin() + static_cast<std::ptrdiff_t>(kVideoHeaderBytes + table));
  return out;
}

VideoFrameView unpack_video_frame(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < kVideoHeaderBytes || std::memcmp(bytes.data(), kMagic, 4) != 0 ||
      bytes[4] > 1 || bytes[5] > 2 || bytes[6] == 1 || bytes[6] > kMaxVideoBands || bytes[7] != 0) {
    throw std::runtime_error("not a video frame: no BCV1 header");
  }
  VideoFrameView v;
  v.key = bytes[4] == 1;
  v.codec = static_cast<VideoCodec>(bytes[5]);
  v.pts = get_u32(bytes.data() + 8);
  const std::size_t bands = bytes[6];
  if (bytes.size() < kVideoHeaderBytes + 4 * bands) throw std::runtime_error("video frame: band sizes cut short");
  v.data = bytes.subspan(kVideoHeaderBytes + 4 * bands);
  if (bands == 0) {
    v.bands.push_back(v.data);
    return v;
  }
  std::size_t offset = 0;
  for (std::size_t i = 0; i < bands; ++i) {
    const std::size_t size = get_u32(bytes.data() + kVideoHeaderBytes + 4 * i);
    if (size > v.data.size() - offset) throw std::runtime_error("video frame: bands longer than the frame");
    v.bands.push_back(v.data.subspan(offset, size));
    offset += size;
  }
  if (offset != v.data.size()) throw std::runtime_error("video frame: bytes after the bands");
  return v;
}

}  // namespace beamcast
