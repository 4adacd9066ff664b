#include "protocol/medium.hpp"

#include <span>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "protocol/json_reader.hpp"

namespace beamcast {

using namespace json_read;

double schlick_k_from_g(double g) { return 1.55 * g - 0.55 * g * g * g; }

namespace {

// sigma_s, sigma_a and the phase (k or g) of a medium object.
template <class M>
void read_coefficients(const ObjectReader& o, M* m) {
  // Up to 1e6 per unit length: optical depth 1 over a micrometre of a
  // metre-sized scene; above it a float's e^(-sigma t) is 0 everywhere.
  constexpr double kMaxCoefficient = 1e6;
  if (auto v = o.optional("sigma_s")) m->sigma_s = check_closed(*v, read_number(*v), 0.0, kMaxCoefficient);
  if (auto v = o.optional("sigma_a")) m->sigma_a = check_closed(*v, read_number(*v), 0.0, kMaxCoefficient);
  const auto k = o.optional("k");
  const auto g = o.optional("g");
  if (k && g) {
    fail("invalid_value", g->path,
         "give the phase function as k (Schlick) or as g (Henyey-Greenstein), not both");
  }
  if (k) m->k = check_open(*k, read_number(*k), -1.0, 1.0);
  if (g) m->k = schlick_k_from_g(check_closed(*g, read_number(*g), -kSchlickMaxG, kSchlickMaxG));
}

}  // namespace

MediumRegion parse_medium_region(const Node& n, double max_abs) {
  ObjectReader o(n, "a medium region");
  o.allow_only(std::span<const std::string_view>(kMediumRegionFields));
  MediumRegion r;
  const Node type = o.required("type");
  r.shape = read_enum<MediumRegion::Shape>(
      type, {{"box", MediumRegion::Shape::kBox}, {"sphere", MediumRegion::Shape::kSphere}});
  auto point = [&](const Node& v) { return check_coordinates(v, read_vec3(v), max_abs); };
  if (r.shape == MediumRegion::Shape::kBox) {
    for (const char* f : {"center", "radius"}) {
      if (auto v = o.optional(f)) fail("unknown_field", v->path, std::string(f) + " is for spheres; a box has min and max");
    }
    r.lo = point(o.required("min"));
    const Node hi = o.required("max");
    r.hi = point(hi);
    for (std::size_t i = 0; i < 3; ++i) {
      if (!(r.hi[i] > r.lo[i])) {
        fail("invalid_value", hi.path, "max must exceed min in every coordinate (an empty box)");
      }
    }
  } else {
    for (const char* f : {"min", "max"}) {
      if (auto v = o.optional(f)) fail("unknown_field", v->path, std::string(f) + " is for boxes; a sphere has center and radius");
    }
    r.lo = point(o.required("center"));
    const Node rad = o.required("radius");
    r.radius = check_positive(rad, read_number(rad));
    if (r.radius > max_abs) fail("out_of_range", rad.path, "radius must be <= " + format_number(max_abs));
  }
  read_coefficients(o, &r);
  return r;
}

bool MediumRegion::contains(const Vec3& x) const {
  if (shape == Shape::kSphere) {
    const Vec3 d = x - lo;
    return dot(d, d) <= radius * radius;
  }
  return x[0] >= lo[0] && x[0] <= hi[0] && x[1] >= lo[1] && x[1] <= hi[1] && x[2] >= lo[2] &&
         x[2] <= hi[2];
}

void MediumRegion::clip(const Vec3& o, const Vec3& v, double* a, double* b) const {
  if (shape == Shape::kSphere) {
    const Vec3 oc = lo - o;
    const double tc = dot(oc, v);
    const Vec3 perp = oc - tc * v;
    const double h2 = radius * radius - dot(perp, perp);
    if (!(h2 > 0.0)) {
      *b = *a;
      return;
    }
    const double h = std::sqrt(h2);
    *a = std::max(*a, tc - h);
    *b = std::min(*b, tc + h);
    return;
  }
  for (std::size_t i = 0; i < 3; ++i) {
    if (v[i] == 0.0) {
      if (o[i] < lo[i] || o[i] > hi[i]) *b = *a;
      continue;
    }
    const double ta = (lo[i] - o[i]) / v[i], tb = (hi[i] - o[i]) / v[i];
    *a = std::max(*a, std::min(ta, tb));
    *b = std::min(*b, std::max(ta, tb));
  }
}

double MediumRegion::chord(const Vec3& o, const Vec3& v, double t0, double t1) const {
  double a = t0, b = t1;
  clip(o, v, &a, &b);
  return b > a ? b - a : 0.0;
}

double MediumRegion::exit(const Vec3& o, const Vec3& v) const {
  double a = 0.0, b = std::numeric_limits<double>::infinity();
  clip(o, v, &a, &b);
  return b > a ? b : -1.0;
}

double MediumField::last_exit(const Vec3& o, const Vec3& v) const {
  if (global_) return std::numeric_limits<double>::infinity();
  double t = -1.0;
  for (const MediumRegion& r : *regions_) t = std::max(t, r.exit(o, v));
  return t;
}

MediumField::MediumField(const Medium* global, const std::vector<MediumRegion>& regions)
    : global_(global), regions_(&regions) {
  majorant_ = global ? global->sigma_t() : 0.0;
  for (const MediumRegion& r : regions) majorant_ += r.sigma_t();
}

double MediumField::sigma_t(const Vec3& x) const {
  double s = global_ ? global_->sigma_t() : 0.0;
  for (const MediumRegion& r : *regions_) {
    if (r.contains(x)) s += r.sigma_t();
  }
  return s;
}

double MediumField::sigma_s(const Vec3& x) const {
  double s = global_ ? global_->sigma_s : 0.0;
  for (const MediumRegion& r : *regions_) {
    if (r.contains(x)) s += r.sigma_s;
  }
  return s;
}

double MediumField::k(const Vec3& x) const {
  double ss = global_ ? global_->sigma_s : 0.0;
  double sk = global_ ? global_->sigma_s * global_->k : 0.0;
  for (const MediumRegion& r : *regions_) {
    if (r.contains(x)) {
      ss += r.sigma_s;
      sk += r.sigma_s * r.k;
    }
  }
  return ss > 0.0 ? sk / ss : 0.0;
}

double MediumField::optical_depth(const Vec3& o, const Vec3& v, double t0, double t1) const {
  if (!(t1 > t0)) return 0.0;
  double tau = global_ ? global_->sigma_t() * (t1 - t0) : 0.0;
  for (const MediumRegion& r : *regions_) tau += r.sigma_t() * r.chord(o, v, t0, t1);
  return tau;
}

Medium parse_medium(const Node& n) {
  ObjectReader o(n, "a medium");
  o.allow_only(std::span<const std::string_view>(kMediumFields));
  Medium m;
  read_coefficients(o, &m);
  if (auto v = o.optional("beam_rule")) {
    m.beam_rule = read_enum<BeamMediumRule>(
        *v, {{"gauss2", BeamMediumRule::kGauss2}, {"midpoint", BeamMediumRule::kMidpoint}});
  }
  // Below 0.05 a piece of optical depth 1.6 already needs every one of the
  // kMaxBeamSubPieces; above 8 one sub-piece spans e^-8 of attenuation.
  if (auto v = o.optional("beam_step")) m.beam_step = check_closed(*v, read_number(*v), 0.05, 8.0);
  if (auto v = o.optional("estimator")) {
    m.estimator = read_enum<VolumeEstimator>(
        *v, {{"beam", VolumeEstimator::kBeam}, {"seed", VolumeEstimator::kSeed}});
  }
  if (auto v = o.optional("radius")) m.radius = check_closed(*v, read_number(*v), 0.0, 1e6);
  if (auto v = o.optional("radius_pixels")) {
    m.radius_pixels = check_closed(*v, read_number(*v), 0.0, 4096.0);
  }
  return m;
}

}  // namespace beamcast
