#include "protocol/beams/capsule.hpp"

#include <algorithm>
#include <limits>
#include <string>

#include "protocol/beams/beam_parse.hpp"

namespace beamcast {

using namespace json_read;

CapsuleBeam CapsuleBeam::parse(const BeamParse& in) {
  CapsuleBeam c;
  c.p0 = read_point(in.fields.required("p0"), in.limits);
  const Node p1 = in.fields.required("p1");
  c.p1 = read_point(p1, in.limits);
  if (auto caps = in.fields.optional("caps")) {
    if (!caps->json().is_array() || caps->json().size() != 2) {
      fail("wrong_type", caps->path,
           "caps must be an array of 2 booleans, got " + describe(caps->json()));
    }
    c.cap0 = read_bool(Node{&caps->json()[0], child_path(caps->path, 0)});
    c.cap1 = read_bool(Node{&caps->json()[1], child_path(caps->path, 1)});
  }
  const double len = length(c.p1 - c.p0);
  if (len <= 1e-9 * std::max(1.0, in.radius)) {
    fail("degenerate_capsule", p1.path,
         "capsule axis length |p1 - p0| = " + format_number(len) +
             " is zero or too small for radius " + format_number(in.radius) +
             "; write a zero-length capsule as a sphere beam instead");
  }
  return c;
}

Aabb CapsuleBeam::defining_bounds() const {
  Aabb b;
  b.grow(p0);
  b.grow(p1);
  return b;
}

BeamGpu CapsuleBeam::gpu(const Vec3& eye) const {
  const Vec3 axis = p1 - p0;
  const double len = length(axis);
  BeamGpu g;
  g.p0 = p0 - eye;
  g.axis = normalize(axis);
  g.length = len;
  g.caps_kind = {cap0 ? 1.0 : 0.0, cap1 ? 1.0 : 0.0, 1.0};
  return g;
}

void CapsuleBeam::reference_axis(double radius, Vec3* w, double* half_len) const {
  const Vec3 axis = p1 - p0;
  const double len = length(axis);
  *w = {0.0, 0.0, 1.0};
  if (len > 0.0) *w = normalize(axis);  // else: degenerate, any axis will do
  *half_len = 0.5 * len * (1.0 / radius);
}

ReferenceFrame CapsuleBeam::reference_frame(double radius) const {
  Vec3 w;
  double half_len = 0.0;
  reference_axis(radius, &w, &half_len);
  return {0.5 * (p0 + p1), (half_len + 1.0) * (half_len + 1.0)};
}

// The ray meets three regions along the axis: before p0 (distance to p0, if
// cap0), the slab between (distance to the axis line), beyond p1 (distance to
// p1, if cap1). u(sigma) = (p - p0) . w = u_q + sigma * vw; the slab is
// 0 <= u <= L.
double CapsuleBeam::reference_energy(const RadialIntegrals& f, const Vec3& q, const Vec3& v,
                                     double s0, double s1, double radius) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Vec3 w;
  double half_len = 0.0;
  reference_axis(radius, &w, &half_len);
  const Vec3 a0 = (-half_len) * w;
  const Vec3 a1 = half_len * w;
  const double len = 2.0 * half_len;
  const double uq = dot(q - a0, w);
  const double vw = dot(v, w);
  // Sigma intervals of the three regions (before cap0 / in the slab / beyond cap1).
  double r0lo, r0hi, slo, shi, r1lo, r1hi;
  if (vw > 0.0) {
    const double su0 = -uq / vw;
    const double suL = (len - uq) / vw;
    r0lo = -kInf, r0hi = su0, slo = su0, shi = suL, r1lo = suL, r1hi = kInf;
  } else if (vw < 0.0) {
    const double su0 = -uq / vw;
    const double suL = (len - uq) / vw;
    r1lo = -kInf, r1hi = suL, slo = suL, shi = su0, r0lo = su0, r0hi = kInf;
  } else {  // perpendicular to the axis: one region for the whole ray
    r0lo = r0hi = slo = shi = r1lo = r1hi = 0.0;
    if (uq < 0.0) {
      r0lo = -kInf, r0hi = kInf;
    } else if (uq > len) {
      r1lo = -kInf, r1hi = kInf;
    } else {
      slo = -kInf, shi = kInf;
    }
  }
  double e = f.line(a0, w, std::max(s0, slo), std::min(s1, shi));
  if (cap0) e += f.point(a0, std::max(s0, r0lo), std::min(s1, r0hi));
  if (cap1) e += f.point(a1, std::max(s0, r1lo), std::min(s1, r1hi));
  return e;
}

}  // namespace beamcast
