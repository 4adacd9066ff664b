// What every beam kind provides, and the small types its functions exchange
// with the parser, the GPU path and the CPU reference. A kind is one struct in
// its own files here (sphere, capsule) holding its geometry; the fields every
// beam shares (radius, color, intensity, density) stay in Beam (scene.hpp).
//   static constexpr std::string_view kType;  its "type" in scene JSON
//   static constexpr std::array kFields;      its own JSON keys
//   static T parse(const BeamParse& in);      validation, JSON-pointer errors
//   Aabb defining_bounds() const;             bounds of its centre / axis ends
//   BeamGpu gpu(const Vec3& eye) const;       the beam shader's record
//   ReferenceFrame reference_frame(double radius) const;   CPU reference:
//   double reference_energy(const RadialIntegrals&, q, v, s0, s1, radius) const;
// Dispatch over the kinds is std::visit over BeamShape (beams.hpp), so a kind
// that lacks one of these does not compile where it is used.
#pragma once

#include "protocol/vec.hpp"

namespace beamcast {

struct BeamParse;  // beam_parse.hpp

// A kind's record for shaders/beam.frag (BeamData in render/scene_resources):
// camera-relative and computed in double, converted to float there. A sphere
// is a capsule of zero length with no caps in this record (caps_kind.z = 0).
struct BeamGpu {
  Vec3 p0{};                    // centre, or the axis start, minus the eye
  Vec3 axis{0.0, 0.0, 1.0};     // unit axis (capsule)
  double length = 0.0;          // axis length (capsule)
  Vec3 caps_kind{0.0, 0.0, 0.0};  // cap0, cap1 (0/1), kind (0 sphere, 1 capsule)
};

// The distance from the eye (the origin of g's camera-relative frame) to the
// box that shaders/beam.vert draws around the beam (0 when the eye is inside),
// in double. A capsule's box has a square cross-section of half-width r whose
// rotation about the axis the shader picks; this takes its circumscribed
// cylinder (radius r sqrt 2), so it never exceeds the true distance.
double proxy_box_distance(const BeamGpu& g, double radius);

// The CPU reference works about the centre C of the beam's bounding sphere, in
// units of the radius r (render/reference.cpp): `bound2` is the squared
// bounding radius in those units.
struct ReferenceFrame {
  Vec3 c{};
  double bound2 = 1.0;
};

// The reference's integrals of the density f along one ray q + sigma v
// (relative to C, units of r, |v| = 1) over sigma in [lo, hi]: a kind splits
// its ray into pieces where the distance is measured to a point or to a line,
// and sums these. Implemented once, in render/reference.cpp, for every kind.
class RadialIntegrals {
 public:
  // f(|p(sigma) - a|)
  virtual double point(const Vec3& a, double lo, double hi) const = 0;
  // f(distance from p(sigma) to the line through a with unit direction w)
  virtual double line(const Vec3& a, const Vec3& w, double lo, double hi) const = 0;

 protected:
  ~RadialIntegrals() = default;
};

}  // namespace beamcast
