#include "protocol/beams/sphere.hpp"

#include "protocol/beams/beam_parse.hpp"

namespace beamcast {

SphereBeam SphereBeam::parse(const BeamParse& in) {
  return SphereBeam{json_read::read_point(in.fields.required("center"), in.limits)};
}

Aabb SphereBeam::defining_bounds() const {
  Aabb b;
  b.grow(center);
  return b;
}

BeamGpu SphereBeam::gpu(const Vec3& eye) const {
  BeamGpu g;
  g.p0 = center - eye;
  return g;
}

ReferenceFrame SphereBeam::reference_frame(double /*radius*/) const { return {center, 1.0}; }

double SphereBeam::reference_energy(const RadialIntegrals& f, const Vec3& /*q*/,
                                    const Vec3& /*v*/, double s0, double s1,
                                    double /*radius*/) const {
  return f.point(Vec3{0.0, 0.0, 0.0}, s0, s1);
}

}  // namespace beamcast
