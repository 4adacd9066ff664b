// A linear HDR image: the plain buffer that the GPU renderer reads back, the
// CPU reference and the CPU photon gather (gi/) write. Here, below gi/ and
// render/, so both can use it; the rest of the image code (tone mapping, PNG,
// error metrics) is render/image.hpp.
#pragma once

#include <cstddef>
#include <vector>

namespace beamcast {

// Linear radiance/energy, RGB, rows from the top of the picture down.
struct HdrImage {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;  // 3 * width * height
  float* at(int x, int y) { return &rgb[3 * (static_cast<std::size_t>(y) * width + x)]; }
  const float* at(int x, int y) const {
    return &rgb[3 * (static_cast<std::size_t>(y) * width + x)];
  }
};

}  // namespace beamcast
