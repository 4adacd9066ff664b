// Vectors in double precision and the small helpers used across the project
// (implemented in camera.cpp).
#pragma once

#include <array>
#include <limits>

namespace beamcast {

using Vec3 = std::array<double, 3>;
using Color = std::array<double, 3>;  // linear RGB

inline Vec3 operator+(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 operator-(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 operator*(double s, const Vec3& a) { return {s * a[0], s * a[1], s * a[2]}; }
// Componentwise product (colours: filters, reflectances).
inline Vec3 mul(const Vec3& a, const Vec3& b) { return {a[0] * b[0], a[1] * b[1], a[2] * b[2]}; }
inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double length(const Vec3& a);
Vec3 normalize(const Vec3& a);
// Rotates v by the unit quaternion q = (w, x, y, z).
Vec3 rotate(const std::array<double, 4>& q, const Vec3& v);

// World-space axis-aligned bounds; empty until grown.
struct Aabb {
  Vec3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          std::numeric_limits<double>::infinity()};
  Vec3 hi{-lo[0], -lo[1], -lo[2]};
  bool empty() const { return !(lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2]); }
  void grow(const Vec3& p) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = p[k] < lo[k] ? p[k] : lo[k];
      hi[k] = p[k] > hi[k] ? p[k] : hi[k];
    }
  }
  void grow(const Aabb& b) {
    if (b.empty()) return;
    grow(b.lo);
    grow(b.hi);
  }
  Vec3 centre() const { return 0.5 * (lo + hi); }
};

}  // namespace beamcast
