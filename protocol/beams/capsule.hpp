// Beam "capsule": density f(distance to the segment p0-p1 / radius); the
// hemispheres beyond p0 and p1 (the caps) may each be left off, which cuts the
// beam flat there.
#pragma once

#include <array>
#include <string_view>

#include "protocol/beams/beam_base.hpp"

namespace beamcast {

struct CapsuleBeam {
  static constexpr std::string_view kType = "capsule";
  static constexpr std::array<std::string_view, 3> kFields{"p0", "p1", "caps"};
  Vec3 p0{};
  Vec3 p1{};
  bool cap0 = true;  // hemisphere beyond p0
  bool cap1 = true;  // hemisphere beyond p1

  static CapsuleBeam parse(const BeamParse& in);
  Aabb defining_bounds() const;
  BeamGpu gpu(const Vec3& eye) const;
  ReferenceFrame reference_frame(double radius) const;
  double reference_energy(const RadialIntegrals& f, const Vec3& q, const Vec3& v, double s0,
                          double s1, double radius) const;

 private:
  // The axis in the reference's units: unit direction w and L / (2 r).
  void reference_axis(double radius, Vec3* w, double* half_len) const;
};

}  // namespace beamcast
