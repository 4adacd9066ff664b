// Reflection and refraction at smooth surfaces, shared by the photon tracer
// and the path-traced reference. Directions are unit vectors; `n` is the
// unit normal on the side the incoming direction comes from (dot(d, n) < 0).
#pragma once

#include <cmath>
#include <optional>

#include "protocol/vec.hpp"

namespace beamcast {

// Mirror reflection of the travel direction d about n.
inline Vec3 reflect(const Vec3& d, const Vec3& n) { return d - (2.0 * dot(d, n)) * n; }

// Fresnel reflectance for unpolarized light going from a medium of index
// n1 into one of n2, at cos_i = cos(angle of incidence) in [0, 1]: the mean of
// the s and p reflectances; 1 past the critical angle (total internal
// reflection).
inline double fresnel_dielectric(double cos_i, double n1, double n2) {
  const double eta = n1 / n2;
  const double sin_t2 = eta * eta * (1.0 - cos_i * cos_i);
  if (sin_t2 >= 1.0) return 1.0;
  const double cos_t = std::sqrt(1.0 - sin_t2);
  const double rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
  const double rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

// The refracted travel direction from index n1 into n2 (Snell's law), or none
// past the critical angle.
inline std::optional<Vec3> refract(const Vec3& d, const Vec3& n, double n1, double n2) {
  const double eta = n1 / n2;
  const double cos_i = -dot(d, n);
  const double sin_t2 = eta * eta * (1.0 - cos_i * cos_i);
  if (sin_t2 >= 1.0) return std::nullopt;
  const double cos_t = std::sqrt(1.0 - sin_t2);
  return eta * d + (eta * cos_i - cos_t) * n;
}

}  // namespace beamcast
