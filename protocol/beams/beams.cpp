#include "protocol/beams/beams.hpp"

#include <algorithm>
#include <cmath>

#include "protocol/kinds.hpp"

namespace beamcast {

std::vector<std::string_view> beam_types() { return kind_types<BeamShape>(); }

double proxy_box_distance(const BeamGpu& g, double radius) {
  const Vec3 e = -1.0 * g.p0;  // the eye relative to the centre or axis start
  if (g.caps_kind[2] < 0.5) {  // sphere: the axis-aligned cube p0 +- r
    double d2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double out = std::max(std::abs(e[k]) - radius, 0.0);
      d2 += out * out;
    }
    return std::sqrt(d2);
  }
  const double lo = g.caps_kind[0] > 0.5 ? -radius : 0.0;
  const double hi = g.length + (g.caps_kind[1] > 0.5 ? radius : 0.0);
  const double along = dot(e, g.axis);
  const double radial = length(e - along * g.axis);
  const double past_ends = std::max({lo - along, along - hi, 0.0});
  const double past_side = std::max(radial - std::sqrt(2.0) * radius, 0.0);
  return std::hypot(past_ends, past_side);
}

}  // namespace beamcast
