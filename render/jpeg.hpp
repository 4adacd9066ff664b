// JPEG encoding of interactive preview frames (libturbojpeg). Lossy: still
// frames stay PNG (image.hpp); docs/performance.md compares the two.
#pragma once

#include <cstdint>
#include <vector>

#include "render/image.hpp"

namespace beamcast {

// Baseline JPEG, 4:2:0 chroma subsampling, `quality` 1..100. 16-bit images
// are reduced to 8 bits. Throws std::runtime_error if libturbojpeg fails.
std::vector<std::uint8_t> encode_jpeg(const Image& img, int quality);

// Decodes a JPEG into 8-bit RGB (tests and benchmarks).
Image decode_jpeg(const std::vector<std::uint8_t>& jpeg);

}  // namespace beamcast
