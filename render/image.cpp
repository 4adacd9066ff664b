#include "render/image.hpp"

#include <libdeflate.h>
#include <png.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>

#include "protocol/check.hpp"

namespace beamcast {

double tone_curve(ToneCurve curve, double x) {
  switch (curve) {
    case ToneCurve::kExponential:
      return 1.0 - std::exp(-x);
    case ToneCurve::kReinhard:
      return x / (1.0 + x);
    case ToneCurve::kClamp:
      return std::min(x, 1.0);
  }
  return x;
}

double srgb_encode(double linear) {
  if (linear <= 0.0031308) return 12.92 * linear;
  return 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

namespace {

void check_bit_depth(int bit_depth) {
  if (bit_depth != 8 && bit_depth != 16) {
    throw std::invalid_argument("bit depth " + std::to_string(bit_depth) + " is not 8 or 16");
  }
}

int max_level(int bit_depth) { return bit_depth == 16 ? 65535 : 255; }

// Tone curve and clamp to [0, 1]; NaN and -inf give 0, +inf gives 1.
double display_linear(ToneCurve curve, double x) {
  if (std::isnan(x) || x <= 0.0) return 0.0;
  if (std::isinf(x)) return 1.0;
  const double c = tone_curve(curve, x);
  if (!(c >= 0.0)) return 0.0;
  return std::min(c, 1.0);
}

}  // namespace

Image tone_map(const HdrImage& hdr, const OutputSettings& out) {
  check_bit_depth(out.bit_depth);
  Image img;
  img.width = hdr.width;
  img.height = hdr.height;
  img.bit_depth = out.bit_depth;
  img.rgb.resize(hdr.rgb.size());
  const double maxv = max_level(out.bit_depth);
  for (std::size_t i = 0; i < hdr.rgb.size(); ++i) {
    const double c = display_linear(out.tone, out.exposure * static_cast<double>(hdr.rgb[i]));
    const double e = std::clamp(srgb_encode(c), 0.0, 1.0);
    img.rgb[i] = static_cast<std::uint16_t>(std::lround(e * maxv));
  }
  return img;
}

// ---------------------------------------------------------------------------
// PNG

namespace {

void png_error_fn(png_structp png, png_const_charp msg) {
  // Keep the message for the exception thrown after longjmp.
  auto* where = static_cast<std::string*>(png_get_error_ptr(png));
  if (where) *where = msg ? msg : "unknown libpng error";
  png_longjmp(png, 1);
}

void png_warning_fn(png_structp, png_const_charp) {}

void png_write_to_vector(png_structp png, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + length);
}

void png_flush_noop(png_structp) {}

struct ReadSource {
  const std::vector<std::uint8_t>* bytes;
  std::size_t pos;
};

void png_read_from_vector(png_structp png, png_bytep data, png_size_t length) {
  auto* src = static_cast<ReadSource*>(png_get_io_ptr(png));
  if (length > src->bytes->size() - src->pos) png_error(png, "unexpected end of PNG data");
  std::memcpy(data, src->bytes->data() + src->pos, length);
  src->pos += length;
}

void check_image(const Image& img) {
  check_bit_depth(img.bit_depth);
  if (img.width <= 0 || img.height <= 0 ||
      img.rgb.size() != 3 * static_cast<std::size_t>(img.width) * img.height) {
    throw std::invalid_argument("image size " + std::to_string(img.width) + "x" +
                                std::to_string(img.height) + " does not match its " +
                                std::to_string(img.rgb.size()) + " channel values");
  }
}

}  // namespace

std::vector<std::uint8_t> encode_png(const Image& img, int level, int filters) {
  check_image(img);
  if (level < 0 || level > 9) throw std::invalid_argument("PNG compression level must be 0..9");

  // Everything with a destructor is set up before setjmp.
  const int bytes_per_sample = img.bit_depth / 8;
  const std::size_t row_bytes = 3 * static_cast<std::size_t>(img.width) * bytes_per_sample;
  std::vector<std::uint8_t> pixels(row_bytes * img.height);
  for (std::size_t i = 0; i < img.rgb.size(); ++i) {
    const std::uint16_t v = img.rgb[i];
    if (bytes_per_sample == 1) {
      pixels[i] = static_cast<std::uint8_t>(std::min<std::uint16_t>(v, 255));
    } else {  // PNG stores 16-bit samples big-endian
      pixels[2 * i] = static_cast<std::uint8_t>(v >> 8);
      pixels[2 * i + 1] = static_cast<std::uint8_t>(v & 0xff);
    }
  }
  std::vector<png_bytep> rows(img.height);
  for (int y = 0; y < img.height; ++y) rows[y] = pixels.data() + row_bytes * y;
  std::vector<std::uint8_t> out;
  out.reserve(row_bytes * img.height / 2 + 1024);
  std::string error;

  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, png_error_fn, png_warning_fn);
  if (!png) throw std::runtime_error("png_create_write_struct failed");
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    throw std::runtime_error("png_create_info_struct failed");
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("PNG encoding failed: " + error);
  }
  png_set_write_fn(png, &out, png_write_to_vector, png_flush_noop);
  png_set_compression_level(png, level);
  if (filters >= 0) png_set_filter(png, PNG_FILTER_TYPE_BASE, filters);
  png_set_IHDR(png, info, static_cast<png_uint_32>(img.width), static_cast<png_uint_32>(img.height),
               img.bit_depth, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_BASE,
               PNG_FILTER_TYPE_BASE);
  png_write_info(png, info);
  png_write_image(png, rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

namespace {

void put_be32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<std::uint8_t>(v >> shift));
}

// One PNG chunk: length, type, data, CRC-32 of type and data.
void put_chunk(std::vector<std::uint8_t>& out, const char type[4], const std::uint8_t* data,
               std::size_t size) {
  put_be32(out, static_cast<std::uint32_t>(size));
  const std::size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data, data + size);
  put_be32(out, libdeflate_crc32(0, out.data() + start, size + 4));
}

// A compressor per level and thread: allocating one costs more than
// compressing a small frame at level 1.
libdeflate_compressor* deflate_compressor(int level) {
  thread_local struct Cache {
    std::array<libdeflate_compressor*, 13> c{};
    ~Cache() {
      for (auto* p : c) libdeflate_free_compressor(p);
    }
  } cache;
  auto*& c = cache.c[static_cast<std::size_t>(level)];
  if (!c) c = libdeflate_alloc_compressor(level);
  if (!c) throw std::runtime_error("libdeflate_alloc_compressor failed");
  return c;
}

}  // namespace

std::vector<std::uint8_t> encode_png_libdeflate(const Image& img, int level, PngRowFilter filter) {
  check_image(img);
  if (level < 0 || level > 12) throw std::invalid_argument("libdeflate level must be 0..12");
  // Scanlines: the filter type byte, then the row's samples (16-bit ones
  // big-endian), filtered against the pixel to the left (sub) or above (up).
  const std::size_t bps = static_cast<std::size_t>(img.bit_depth / 8);  // bytes a sample
  const std::size_t bpp = 3 * bps;
  const std::size_t row_bytes = bpp * static_cast<std::size_t>(img.width);
  std::vector<std::uint8_t> row(row_bytes), prev(row_bytes, 0);
  std::vector<std::uint8_t> lines((row_bytes + 1) * static_cast<std::size_t>(img.height));
  for (int y = 0; y < img.height; ++y) {
    const std::uint16_t* src = img.rgb.data() + 3 * static_cast<std::size_t>(img.width) * y;
    if (bps == 1) {
      for (std::size_t i = 0; i < row_bytes; ++i) row[i] = static_cast<std::uint8_t>(src[i]);
    } else {
      for (std::size_t i = 0; i < row_bytes / 2; ++i) {
        row[2 * i] = static_cast<std::uint8_t>(src[i] >> 8);
        row[2 * i + 1] = static_cast<std::uint8_t>(src[i] & 0xff);
      }
    }
    std::uint8_t* out = lines.data() + (row_bytes + 1) * static_cast<std::size_t>(y);
    *out++ = static_cast<std::uint8_t>(filter);
    switch (filter) {
      case PngRowFilter::kNone:
        std::memcpy(out, row.data(), row_bytes);
        break;
      case PngRowFilter::kSub:
        for (std::size_t i = 0; i < bpp; ++i) out[i] = row[i];
        for (std::size_t i = bpp; i < row_bytes; ++i) {
          out[i] = static_cast<std::uint8_t>(row[i] - row[i - bpp]);
        }
        break;
      case PngRowFilter::kUp:
        for (std::size_t i = 0; i < row_bytes; ++i) {
          out[i] = static_cast<std::uint8_t>(row[i] - prev[i]);
        }
        break;
    }
    std::swap(row, prev);
  }
  libdeflate_compressor* c = deflate_compressor(level);
  std::vector<std::uint8_t> z(libdeflate_zlib_compress_bound(c, lines.size()));
  const std::size_t zsize = libdeflate_zlib_compress(c, lines.data(), lines.size(), z.data(), z.size());
  BEAMCAST_CHECK(zsize > 0, "libdeflate_zlib_compress: output larger than its own bound");
  std::vector<std::uint8_t> out;
  out.reserve(zsize + 64);
  const std::uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  out.insert(out.end(), signature, signature + 8);
  std::vector<std::uint8_t> ihdr;
  put_be32(ihdr, static_cast<std::uint32_t>(img.width));
  put_be32(ihdr, static_cast<std::uint32_t>(img.height));
  // bit depth, colour type 2 (RGB), deflate, adaptive filtering, no interlace
  ihdr.insert(ihdr.end(), {static_cast<std::uint8_t>(img.bit_depth), 2, 0, 0, 0});
  put_chunk(out, "IHDR", ihdr.data(), ihdr.size());
  put_chunk(out, "IDAT", z.data(), zsize);
  put_chunk(out, "IEND", nullptr, 0);
  return out;
}

std::vector<std::uint8_t> encode_png(const Image& img, const PngSettings& s) {
  return s.encoder == PngEncoder::kLibdeflate ? encode_png_libdeflate(img, s.level, s.row_filter)
                                              : encode_png(img, s.level, s.libpng_filters);
}

void write_png(const std::filesystem::path& file, const Image& img) {
  const std::vector<std::uint8_t> bytes = encode_png(img);
  std::ofstream os(file, std::ios::binary | std::ios::trunc);
  if (!os) throw std::runtime_error("cannot open " + file.string() + " for writing");
  os.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!os) throw std::runtime_error("cannot write " + file.string());
}

Image decode_png(const std::vector<std::uint8_t>& bytes) {
  if (bytes.size() < 8 || png_sig_cmp(bytes.data(), 0, 8) != 0) {
    throw std::runtime_error("not a PNG (bad signature)");
  }
  ReadSource src{&bytes, 0};
  std::string error;
  Image img;
  std::vector<std::uint8_t> pixels;
  std::vector<png_bytep> rows;

  png_structp png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, &error, png_error_fn, png_warning_fn);
  if (!png) throw std::runtime_error("png_create_read_struct failed");
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    throw std::runtime_error("png_create_info_struct failed");
  }
  // No C++ object is created between setjmp and the last libpng call below
  // (the vectors are resized, which is fine: longjmp only skips destructors of
  // objects constructed after setjmp).
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw std::runtime_error("PNG decoding failed: " + error);
  }
  png_set_read_fn(png, &src, png_read_from_vector);
  png_read_info(png, info);
  const png_uint_32 width = png_get_image_width(png, info);
  const png_uint_32 height = png_get_image_height(png, info);
  const int depth = png_get_bit_depth(png, info);
  const int color = png_get_color_type(png, info);
  if (color == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (color == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (color == PNG_COLOR_TYPE_GRAY || color == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(png);
  if (color & PNG_COLOR_MASK_ALPHA) png_set_strip_alpha(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  const int out_depth = png_get_bit_depth(png, info);
  const int channels = png_get_channels(png, info);
  if (channels != 3 || (out_depth != 8 && out_depth != 16)) {
    png_error(png, "unsupported PNG layout after conversion");
  }
  const std::size_t row_bytes = png_get_rowbytes(png, info);
  pixels.resize(row_bytes * height);
  rows.resize(height);
  for (png_uint_32 y = 0; y < height; ++y) rows[y] = pixels.data() + row_bytes * y;
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);

  img.width = static_cast<int>(width);
  img.height = static_cast<int>(height);
  img.bit_depth = out_depth;
  img.rgb.resize(3 * static_cast<std::size_t>(width) * height);
  for (png_uint_32 y = 0; y < height; ++y) {
    const std::uint8_t* row = pixels.data() + row_bytes * y;
    std::uint16_t* dst = &img.rgb[3 * static_cast<std::size_t>(width) * y];
    for (std::size_t k = 0; k < 3 * static_cast<std::size_t>(width); ++k) {
      dst[k] = out_depth == 8 ? row[k]
                              : static_cast<std::uint16_t>((row[2 * k] << 8) | row[2 * k + 1]);
    }
  }
  return img;
}

Image read_png(const std::filesystem::path& file) {
  std::ifstream is(file, std::ios::binary);
  if (!is) throw std::runtime_error("cannot open " + file.string());
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(is)),
                                  std::istreambuf_iterator<char>());
  try {
    return decode_png(bytes);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(file.string() + ": " + e.what());
  }
}

// ---------------------------------------------------------------------------
// Metrics

HdrError compare_hdr(const HdrImage& img, const HdrImage& ref) {
  BEAMCAST_CHECK(
      img.width == ref.width && img.height == ref.height && img.rgb.size() == ref.rgb.size(),
      "compare_hdr: image sizes differ");
  HdrError e;
  double sum_sq = 0.0;
  double sum_abs = 0.0;
  double sum_ref = 0.0;
  std::int64_t counted = 0;
  for (std::size_t i = 0; i < img.rgb.size(); ++i) {
    const double a = img.rgb[i];
    const double r = ref.rgb[i];
    if (!std::isfinite(a)) {  // counted, and kept out of every other metric
      ++e.nonfinite;
      continue;
    }
    if (!std::isfinite(r)) continue;  // a broken reference says nothing about img
    const double diff = std::abs(a - r);
    e.max_abs = std::max(e.max_abs, diff);
    sum_sq += diff * diff;
    sum_abs += diff;
    sum_ref += std::abs(r);
    ++counted;
  }
  e.rms = counted > 0 ? std::sqrt(sum_sq / static_cast<double>(counted)) : 0.0;
  if (sum_ref > 0.0) {
    e.rel_l1 = sum_abs / sum_ref;
  } else {
    e.rel_l1 = sum_abs > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
  }
  return e;
}

namespace {
void check_same_layout(const Image& img, const Image& ref, const char* what) {
  BEAMCAST_CHECK(img.width == ref.width && img.height == ref.height &&
                     img.bit_depth == ref.bit_depth && img.rgb.size() == ref.rgb.size(),
                 std::string(what) + ": images differ in size or bit depth");
}
}  // namespace

LevelError compare_levels(const Image& img, const Image& ref, int threshold) {
  check_same_layout(img, ref, "compare_levels");
  LevelError e;
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < img.rgb.size(); ++i) {
    const int diff = std::abs(static_cast<int>(img.rgb[i]) - static_cast<int>(ref.rgb[i]));
    e.max_abs = std::max(e.max_abs, diff);
    sum_sq += static_cast<double>(diff) * diff;
    if (diff > threshold) ++e.over;
  }
  const double mse = img.rgb.empty() ? 0.0 : sum_sq / static_cast<double>(img.rgb.size());
  e.rms = std::sqrt(mse);
  if (mse == 0.0) {
    e.psnr_db = std::numeric_limits<double>::infinity();
  } else {
    const double peak = max_level(img.bit_depth);
    e.psnr_db = 10.0 * std::log10(peak * peak / mse);
  }
  return e;
}

Image diff_image(const Image& img, const Image& ref) {
  check_same_layout(img, ref, "diff_image");
  Image out;
  out.width = img.width;
  out.height = img.height;
  out.bit_depth = img.bit_depth;
  out.rgb.resize(img.rgb.size());
  int max_diff = 0;
  for (std::size_t i = 0; i < img.rgb.size(); ++i) {
    max_diff = std::max(max_diff, std::abs(static_cast<int>(img.rgb[i]) - static_cast<int>(ref.rgb[i])));
  }
  if (max_diff == 0) return out;  // all black
  const double scale = static_cast<double>(max_level(img.bit_depth)) / max_diff;
  for (std::size_t i = 0; i < img.rgb.size(); ++i) {
    const int diff = std::abs(static_cast<int>(img.rgb[i]) - static_cast<int>(ref.rgb[i]));
    out.rgb[i] = static_cast<std::uint16_t>(std::lround(diff * scale));
  }
  return out;
}

}  // namespace beamcast
