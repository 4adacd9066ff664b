// Beam "sphere": density f(|p - center| / radius).
#pragma once

#include <array>
#include <string_view>

#include "protocol/beams/beam_base.hpp"

namespace beamcast {

struct SphereBeam {
  static constexpr std::string_view kType = "sphere";
  static constexpr std::array<std::string_view, 1> kFields{"center"};
  Vec3 center{};

  static SphereBeam parse(const BeamParse& in);
  Aabb defining_bounds() const;
  BeamGpu gpu(const Vec3& eye) const;
  ReferenceFrame reference_frame(double radius) const;
  double reference_energy(const RadialIntegrals& f, const Vec3& q, const Vec3& v, double s0,
                          double s1, double radius) const;
};

}  // namespace beamcast
