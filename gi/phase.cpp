#include "gi/phase.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace beamcast {

double schlick_phase(double k, double mu) {
  const double d = 1.0 - k * mu;
  return (1.0 - k * k) / (4.0 * std::numbers::pi * d * d);
}

double schlick_sample_mu(double k, double xi) {
  const double mu = (2.0 * xi + k - 1.0) / (2.0 * k * xi - k + 1.0);
  return std::clamp(mu, -1.0, 1.0);
}

double schlick_cdf(double k, double mu) {
  // 2 pi * int_{-1}^{mu} (1 - k^2) / (4 pi (1 - k s)^2) ds
  //   = (1 - k^2) / 2 * [1 / (k (1 - k s))]_{-1}^{mu}
  //   = (1 - k^2) (1 + mu) / (2 (1 + k) (1 - k mu))   (no division by k).
  return (1.0 - k) * (1.0 + mu) / (2.0 * (1.0 - k * mu));
}

Vec3 schlick_sample_direction(double k, const Vec3& travel, double xi1, double xi2) {
  const double mu = schlick_sample_mu(k, xi1);
  const double s = std::sqrt(std::max(0.0, 1.0 - mu * mu));
  const double phi = 2.0 * std::numbers::pi * xi2;
  // An orthonormal frame (a, b, travel) (Duff et al. 2017).
  const double sign = std::copysign(1.0, travel[2]);
  const double e = -1.0 / (sign + travel[2]);
  const double f = travel[0] * travel[1] * e;
  const Vec3 a{1.0 + sign * travel[0] * travel[0] * e, sign * f, -sign * travel[0]};
  const Vec3 b{f, sign + travel[1] * travel[1] * e, -travel[1]};
  return (s * std::cos(phi)) * a + (s * std::sin(phi)) * b + mu * travel;
}

}  // namespace beamcast
