#include "protocol/medium.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <variant>

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

MediumRegion parse_medium_region(const Node& n, const SceneLoadOptions& opts,
                                 std::int64_t* mesh_triangles) {
  const ObjectReader o(n, "a medium region");
  MediumRegion r;
  r.shape = parse_region_shape(o.required("type"), RegionParse{o, opts, mesh_triangles});
  read_coefficients(o, &r);
  return r;
}

Aabb MediumRegion::bounds() const {
  return std::visit([](const auto& kind) { return kind.bounds(); }, shape);
}

bool MediumRegion::contains(const Vec3& x) const {
  return std::visit([&](const auto& kind) { return kind.contains(x); }, shape);
}

double MediumRegion::chord(const Vec3& o, const Vec3& v, double t0, double t1) const {
  return std::visit([&](const auto& kind) { return kind.chord(o, v, t0, t1); }, shape);
}

double MediumRegion::exit(const Vec3& o, const Vec3& v) const {
  return std::visit([&](const auto& kind) { return kind.exit(o, v); }, shape);
}

void MediumRegion::crossings(const Vec3& o, const Vec3& v, double t_end,
                             std::vector<double>* out) const {
  std::visit([&](const auto& kind) { kind.crossings(o, v, t_end, out); }, shape);
}

RegionGpu MediumRegion::gpu() const {
  return std::visit([](const auto& kind) { return kind.gpu(); }, shape);
}

RegionTriangles MediumRegion::gpu_triangles() const {
  return std::visit([](const auto& kind) { return kind.gpu_triangles(); }, shape);
}

namespace {

// Where o + t v (t >= 0) leaves the cube |x_i| <= kMediumExtent; 0 if o is outside it.
double extent_exit(const Vec3& o, const Vec3& v) {
  double t = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < 3; ++i) {
    if (!(std::abs(o[i]) <= kMediumExtent)) return 0.0;
    if (v[i] != 0.0) t = std::min(t, ((v[i] > 0.0 ? kMediumExtent : -kMediumExtent) - o[i]) / v[i]);
  }
  return t;
}

}  // namespace

double MediumField::free_path(const Vec3& o, const Vec3& v, double t_end, double tau) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  t_end = std::min(t_end, extent_exit(o, v));
  if (!(t_end > 0.0) || !(tau >= 0.0)) return kInf;
  if (regions_->empty()) {
    // Homogeneous: t = tau / sigma_t (the same numbers as delta tracking,
    // every tentative event of which is real here).
    const double sigma = global_ ? global_->sigma_t() : 0.0;
    if (!(sigma > 0.0)) return kInf;
    const double t = tau / sigma;
    return t < t_end ? t : kInf;
  }
  std::vector<double> cuts;
  for (const MediumRegion& r : *regions_) r.crossings(o, v, t_end, &cuts);
  cuts.push_back(t_end);
  std::sort(cuts.begin(), cuts.end());
  double t0 = 0.0;
  for (const double t1 : cuts) {
    if (!(t1 > t0)) continue;
    // Exact on [t0, t1], where the extinction is constant: depth / (t1 - t0).
    const double depth = optical_depth(o, v, t0, t1);
    if (depth > 0.0 && depth >= tau) return t0 + (t1 - t0) * (tau / depth);
    tau -= depth;
    t0 = t1;
  }
  return kInf;
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
        *v, {{"grid", VolumeEstimator::kGrid},
             {"beam", VolumeEstimator::kBeam},
             {"seed", VolumeEstimator::kSeed}});
  }
  if (auto v = o.optional("radius")) m.radius = check_closed(*v, read_number(*v), 0.0, 1e6);
  // At most 256: far past where the error stops falling (docs/media.md).
  if (auto v = o.optional("segments")) {
    m.segments =
        static_cast<int>(check_closed(*v, static_cast<double>(read_integer(*v)), 0.0, 256.0));
  }
  if (auto v = o.optional("radius_pixels")) {
    m.radius_pixels = check_closed(*v, read_number(*v), 0.0, 4096.0);
  }
  return m;
}

}  // namespace beamcast
