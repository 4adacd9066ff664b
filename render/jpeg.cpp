#include "render/jpeg.hpp"

#include <turbojpeg.h>

#include <memory>
#include <stdexcept>
#include <string>

#include "protocol/check.hpp"

namespace beamcast {
namespace {

struct TjHandle {
  tjhandle h;
  explicit TjHandle(tjhandle handle) : h(handle) {
    if (!h) throw std::runtime_error(std::string("libturbojpeg: init: ") + tjGetErrorStr2(nullptr));
  }
  ~TjHandle() { tjDestroy(h); }
  TjHandle(const TjHandle&) = delete;
  TjHandle& operator=(const TjHandle&) = delete;
};

}  // namespace

std::vector<std::uint8_t> encode_jpeg(const Image& img, int quality) {
  BEAMCAST_CHECK(img.width > 0 && img.height > 0, "encode_jpeg: empty image");
  std::vector<unsigned char> rgb(img.rgb.size());
  const int shift = img.bit_depth == 16 ? 8 : 0;
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<unsigned char>(img.rgb[i] >> shift);
  TjHandle tj(tjInitCompress());
  unsigned char* out = nullptr;
  unsigned long size = 0;
  if (tjCompress2(tj.h, rgb.data(), img.width, 0, img.height, TJPF_RGB, &out, &size, TJSAMP_420,
                  quality, TJFLAG_FASTDCT) != 0) {
    const std::string msg = tjGetErrorStr2(tj.h);
    tjFree(out);
    throw std::runtime_error("libturbojpeg: tjCompress2: " + msg);
  }
  std::vector<std::uint8_t> bytes(out, out + size);
  tjFree(out);
  return bytes;
}

Image decode_jpeg(const std::vector<std::uint8_t>& jpeg) {
  TjHandle tj(tjInitDecompress());
  int w = 0, h = 0, sub = 0, cs = 0;
  if (tjDecompressHeader3(tj.h, jpeg.data(), jpeg.size(), &w, &h, &sub, &cs) != 0) {
    throw std::runtime_error(std::string("libturbojpeg: header: ") + tjGetErrorStr2(tj.h));
  }
  std::vector<unsigned char> rgb(3 * static_cast<std::size_t>(w) * h);
  if (tjDecompress2(tj.h, jpeg.data(), jpeg.size(), rgb.data(), w, 0, h, TJPF_RGB, 0) != 0) {
    throw std::runtime_error(std::string("libturbojpeg: decode: ") + tjGetErrorStr2(tj.h));
  }
  Image img;
  img.width = w;
  img.height = h;
  img.bit_depth = 8;
  img.rgb.assign(rgb.begin(), rgb.end());
  return img;
}

}  // namespace beamcast
