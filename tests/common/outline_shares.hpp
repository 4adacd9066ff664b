// The light-outline image tests' yardstick (tests/gl: quad and disk lights
// seen on a black wall): the share of each pixel whose rays meet a light
// lying in the plane z = 0, and how far a frame's red channel is from the
// light's radiance times those shares.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "protocol/camera.hpp"

namespace beamcast::test {

// The share of each pixel (rows from the top, as the HDR image) of kSub x
// kSub rays that meet the plane z = 0 where inside(x, y) holds.
template <class Inside>
std::vector<double> plane_z0_shares(const Camera& cam, int size, Inside&& inside) {
  constexpr int kSub = 32;
  const CameraBasis basis = camera_basis(cam);
  std::vector<double> share(static_cast<std::size_t>(size) * size, 0.0);
  for (int row = 0; row < size; ++row) {
    for (int col = 0; col < size; ++col) {
      int in = 0;
      for (int j = 0; j < kSub; ++j) {
        for (int i = 0; i < kSub; ++i) {
          const double nx = 2.0 * (col + (i + 0.5) / kSub) / size - 1.0;
          const double ny = 1.0 - 2.0 * (row + (j + 0.5) / kSub) / size;
          const Ray r = camera_ray_ndc(cam, basis, nx, ny);
          const double t = -r.origin[2] / r.dir[2];
          if (inside(r.origin[0] + t * r.dir[0], r.origin[1] + t * r.dir[1])) ++in;
        }
      }
      share[static_cast<std::size_t>(row) * size + col] = static_cast<double>(in) / (kSub * kSub);
    }
  }
  return share;
}

struct OutlineError {
  double relative_l1 = 0.0;  // sum |red - L share| / sum L share
  int lost = 0;  // pixels with a share of at least `mostly` that read under a fifth of it
};

inline OutlineError outline_error(const std::vector<float>& rgb, const std::vector<double>& share,
                                  double L, double mostly) {
  OutlineError e;
  double diff = 0.0, total = 0.0;
  for (std::size_t p = 0; p < share.size(); ++p) {
    diff += std::abs(rgb[3 * p] - L * share[p]);
    total += L * share[p];
    if (share[p] >= mostly && rgb[3 * p] < 0.2 * L * share[p]) ++e.lost;
  }
  e.relative_l1 = diff / total;
  return e;
}

}  // namespace beamcast::test
