// Direction and point sampling shared by the light kinds and the tracers
// (gi/): every function maps uniform numbers in [0, 1) to a sample.
#pragma once

#include <cmath>
#include <numbers>

#include "protocol/vec.hpp"

namespace beamcast {

// Two unit vectors completing the unit vector n to a right-handed frame
// (Duff et al. 2017, "Building an orthonormal basis, revisited").
inline void orthonormal_basis(const Vec3& n, Vec3* t, Vec3* b) {
  const double sign = std::copysign(1.0, n[2]);
  const double a = -1.0 / (sign + n[2]);
  const double c = n[0] * n[1] * a;
  *t = {1.0 + sign * n[0] * n[0] * a, sign * c, -sign * n[0]};
  *b = {c, sign + n[1] * n[1] * a, -n[1]};
}

// Local (x, y, z) in the frame whose z axis is n.
inline Vec3 from_local(const Vec3& n, double x, double y, double z) {
  Vec3 t, b;
  orthonormal_basis(n, &t, &b);
  return x * t + y * b + z * n;
}

// Uniform over the unit sphere.
inline Vec3 uniform_sphere(double u1, double u2) {
  const double z = 1.0 - 2.0 * u1;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double phi = 2.0 * std::numbers::pi * u2;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Uniform over the cone of directions within acos(cos_max) of n.
inline Vec3 uniform_cone(const Vec3& n, double cos_max, double u1, double u2) {
  const double z = 1.0 - u1 * (1.0 - cos_max);
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double phi = 2.0 * std::numbers::pi * u2;
  return from_local(n, r * std::cos(phi), r * std::sin(phi), z);
}

// Cosine-weighted over the hemisphere about n (pdf cos / pi).
inline Vec3 cosine_hemisphere(const Vec3& n, double u1, double u2) {
  const double r = std::sqrt(u1);
  const double phi = 2.0 * std::numbers::pi * u2;
  return from_local(n, r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u1)));
}

// Calls f(i, j) for every cell of a ku x kv grid, 2 x 2 cells by 2 x 2
// cells in row order, each block's cells in the order (0, 0), (1, 0),
// (0, 1), (1, 1) (a block at an odd edge has fewer): with both even, every
// fourth cell spans the whole grid (the direct pass's interleaved quarters).
template <class F>
void for_each_cell_in_blocks(int ku, int kv, F&& f) {
  for (int bj = 0; bj < kv; bj += 2) {
    for (int bi = 0; bi < ku; bi += 2) {
      for (int k = 0; k < 4; ++k) {
        const int i = bi + (k & 1), j = bj + (k >> 1);
        if (i < ku && j < kv) f(i, j);
      }
    }
  }
}

}  // namespace beamcast
