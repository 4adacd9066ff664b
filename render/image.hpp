// CPU images: linear HDR float buffers, tone-mapped integer images, PNG I/O and
// error metrics. Used by the GPU renderer (after read-back), the CPU reference,
// the tests and the benchmarks. No GL here.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "protocol/hdr_image.hpp"  // HdrImage
#include "protocol/scene.hpp"

namespace beamcast {

// Display-encoded RGB, rows from the top down; values 0..255 (bit_depth 8) or
// 0..65535 (bit_depth 16).
struct Image {
  int width = 0;
  int height = 0;
  int bit_depth = 8;
  std::vector<std::uint16_t> rgb;  // 3 * width * height
};

// The tone curve applied to exposure * E per channel, before sRGB encoding:
//   exponential: 1 - exp(-x)   reinhard: x / (1 + x)   clamp: min(x, 1)
double tone_curve(ToneCurve curve, double x);
// IEC 61966-2-1 sRGB transfer function for a linear value in [0, 1].
double srgb_encode(double linear);
// Tone curve, sRGB and rounding to the bit depth, in double (the CPU side of
// the GPU tone-mapping pass).
Image tone_map(const HdrImage& hdr, const OutputSettings& out);

// PNG encoding with libpng; level 0..9 (zlib), filter as libpng's PNG_FILTER_* mask.
std::vector<std::uint8_t> encode_png(const Image& img, int level = 3, int filters = -1);
// PNG with libdeflate (zlib format, one IDAT chunk) and one row filter for
// every row: the server's default for still frames, 2-4x faster than libpng at
// the same size (docs/performance.md, "Frame encoders"). level 0..12.
enum class PngRowFilter { kNone = 0, kSub = 1, kUp = 2 };  // PNG filter type bytes
std::vector<std::uint8_t> encode_png_libdeflate(const Image& img, int level = 1,
                                                PngRowFilter filter = PngRowFilter::kSub);
// Which encoder and its settings (the server's --png-encoder, --png-level, --png-filter).
enum class PngEncoder { kLibdeflate, kLibpng };
struct PngSettings {
  PngEncoder encoder = PngEncoder::kLibdeflate;
  int level = 1;                                  // libdeflate 0..12, libpng (zlib) 0..9
  PngRowFilter row_filter = PngRowFilter::kSub;   // libdeflate
  int libpng_filters = 0x10;                      // libpng's PNG_FILTER_* mask (SUB)
};
std::vector<std::uint8_t> encode_png(const Image& img, const PngSettings& settings);
void write_png(const std::filesystem::path& file, const Image& img);
// Decodes an 8- or 16-bit RGB or RGBA PNG (alpha dropped); throws std::runtime_error.
Image decode_png(const std::vector<std::uint8_t>& bytes);
Image read_png(const std::filesystem::path& file);

// Error of `img` against `ref` on HDR energy, all channels.
struct HdrError {
  double max_abs = 0.0;  // max |a - r|
  double rms = 0.0;      // sqrt(mean (a - r)^2)
  double rel_l1 = 0.0;   // sum |a - r| / sum |r|  (0 if both are zero)
  std::int64_t nonfinite = 0;  // NaN or Inf values in img
};
HdrError compare_hdr(const HdrImage& img, const HdrImage& ref);

// Error of display images of the same size and bit depth, in levels.
struct LevelError {
  int max_abs = 0;
  double rms = 0.0;
  double psnr_db = 0.0;  // infinity when identical
  std::int64_t over = 0;  // channel values that differ by more than `threshold`
};
LevelError compare_levels(const Image& img, const Image& ref, int threshold = 0);

// A picture of |img - ref| (amplified so the largest difference is white),
// written when an image test fails.
Image diff_image(const Image& img, const Image& ref);

}  // namespace beamcast
