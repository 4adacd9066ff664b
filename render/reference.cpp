#include "render/reference.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>
#include <thread>
#include <variant>
#include <vector>

#include "gi/gi_scene.hpp"
#include "gi/parallel.hpp"
#include "gi/path_tracer.hpp"
#include "protocol/camera.hpp"
#include "render/quadrature.hpp"

namespace beamcast {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------
// Beams
//
// All beam geometry is expressed relative to the centre C of the beam's
// bounding sphere and in units of the radius r, and the ray parameter is
// sigma = (t - t_ref) / r with t_ref the ray's closest approach to C. The
// integral (1/r) * int f(dist/r) dt is then int f(rho(sigma)) dsigma with
// rho = dist / r, all quantities of order one near the beam: exactly invariant
// under scaling the scene, and free of cancellation for far-away cameras.

struct PreparedBeam {
  Vec3 c{};               // bounding-sphere centre (world)
  double r = 1.0;
  double inv_r = 1.0;
  double bound2 = 1.0;    // squared bounding radius, in units of r
  const BeamShape* shape = nullptr;  // the kind splits rays into regions (protocol/beams/)
  const Density* density = nullptr;
  std::vector<double> xb;  // density breakpoints strictly inside (0, 1)
  double fmax = 1.0;
};

PreparedBeam prepare_beam(const Beam& beam) {
  PreparedBeam pb;
  pb.r = beam.radius;
  pb.inv_r = 1.0 / beam.radius;
  pb.density = &beam.density;
  for (double x : beam.density.breakpoints()) {
    if (x > 0.0 && x < 1.0) pb.xb.push_back(x);
  }
  pb.fmax = std::max(1e-300, std::abs(beam.density.max_value()));
  const ReferenceFrame frame =
      std::visit([&](const auto& shape) { return shape.reference_frame(beam.radius); },
                 beam.shape);
  pb.c = frame.c;
  pb.bound2 = frame.bound2;
  pb.shape = &beam.shape;
  return pb;
}

// Small sorted list of integration points; on the stack unless a tabulated
// density brings thousands of breakpoints.
class Points {
 public:
  explicit Points(std::size_t cap) {
    if (cap > kStack) {
      heap_.resize(cap);
      p_ = heap_.data();
    }
  }
  void push(double x) { p_[n_++] = x; }
  // Keeps x only if it lies strictly inside (lo, hi).
  void push_inside(double x, double lo, double hi) {
    if (x > lo && x < hi) p_[n_++] = x;
  }
  void sort() { std::sort(p_, p_ + n_); }
  const double* data() const { return p_; }
  std::size_t size() const { return n_; }

 private:
  static constexpr std::size_t kStack = 64;
  double buf_[kStack];
  std::vector<double> heap_;
  double* p_ = buf_;
  std::size_t n_ = 0;
};

constexpr int kMaxGrading = 16;  // 4^14 > 0.25 / 1e-8: enough levels

// A medium's attenuation along the ray at parameter sigma (world distance
// t = t_ref + r sigma from the ray's origin o, direction v): e^(-optical
// depth over [0, t]) (>= 0 on the visible part: no overflow). Null field:
// none.
struct Attenuation {
  const MediumField* field = nullptr;
  Vec3 o{}, v{};
  double t_ref = 0.0, r = 1.0;
  bool on() const { return field != nullptr; }
  double at(double sigma) const {
    return std::exp(-field->optical_depth(o, v, 0.0, std::max(0.0, t_ref + r * sigma)));
  }
};

// Integral of f(sqrt(d2 + k2 * (sigma - sc)^2)) over [lo, hi], split at the
// closest approach sc and where the distance crosses each density breakpoint.
// k2 = 1 for a sphere, sin^2(theta) for the cylinder; inv_k = 1 / sqrt(k2).
double integrate_radial(const PreparedBeam& pb, double d2, double k2, double inv_k, double sc,
                        double lo, double hi, double rel_tol, const Attenuation& at) {
  if (!(hi > lo)) return 0.0;
  const double d = std::sqrt(d2);
  Points pts(pb.xb.size() * 2 + 3 + 2 * kMaxGrading);
  pts.push(lo);
  pts.push_inside(sc, lo, hi);
  // Graded points |tau| = d 4^k (tau = k (sigma - sc)): for d << 1 the distance
  // bends on the scale d near the closest approach, which one 15-point rule
  // over the whole chord can miss without its error estimate noticing. Below
  // d = 1e-8 that bend is worth < d^2 ln(1/d) ~ 1e-15 of the integral.
  const double chord = std::sqrt((1.0 - d) * (1.0 + d));
  int graded = 0;
  for (double g = std::max(d, 1e-8); d > 0.0 && g < 0.25 * chord && graded < kMaxGrading;
       g *= 4.0, ++graded) {
    pts.push_inside(sc - g * inv_k, lo, hi);
    pts.push_inside(sc + g * inv_k, lo, hi);
  }
  for (double x : pb.xb) {
    if (x > d) {
      const double h = std::sqrt((x - d) * (x + d)) * inv_k;  // no cancellation near x = d
      pts.push_inside(sc - h, lo, hi);
      pts.push_inside(sc + h, lo, hi);
    }
  }
  pts.push(hi);
  pts.sort();
  const Density& f = *pb.density;
  auto integrand = [&f, d2, k2, sc](double s) {
    const double ds = s - sc;
    return f(std::sqrt(d2 + k2 * ds * ds));
  };
  quad::Options opt;
  opt.rel_tol = rel_tol;
  // Absolute floor, relative to the density's scale: an energy 1e4 times below
  // the requested relative accuracy of a unit-size integral is not refined.
  opt.abs_tol = 1e-4 * rel_tol * pb.fmax;
  if (at.on()) {
    // Relative to the light that arrives: the floor scaled by the attenuation
    // at the piece's near end (the most any of it keeps).
    opt.abs_tol *= at.at(lo);
    auto seen = [&](double s) { return integrand(s) * at.at(s); };
    return quad::integrate_pieces(seen, pts.data(), pts.size(), opt).value;
  }
  return quad::integrate_pieces(integrand, pts.data(), pts.size(), opt).value;
}

// Region where the distance is measured to a point `a` (relative, units of r):
// a sphere beam or one end cap of a capsule, restricted to sigma in [lo, hi].
double integrate_point(const PreparedBeam& pb, const Vec3& q, const Vec3& v, const Vec3& a,
                       double lo, double hi, double rel_tol, const Attenuation& at) {
  if (!(hi > lo)) return 0.0;
  const Vec3 e = a - q;
  const double sc = dot(e, v);  // closest approach (dot product, never sqrt(|e|^2 - d^2))
  const Vec3 perp = e - sc * v;
  const double d2 = dot(perp, perp);
  if (!(d2 < 1.0)) return 0.0;
  const double c = std::sqrt((1.0 - std::sqrt(d2)) * (1.0 + std::sqrt(d2)));
  return integrate_radial(pb, d2, 1.0, 1.0, sc, std::max(lo, sc - c), std::min(hi, sc + c),
                          rel_tol, at);
}

// Region where the distance is measured to the axis line through `a0` with unit
// direction w, restricted to sigma in [lo, hi].
double integrate_line(const PreparedBeam& pb, const Vec3& q, const Vec3& v, const Vec3& a0,
                      const Vec3& w, double lo, double hi, double rel_tol, const Attenuation& at) {
  if (!(hi > lo)) return 0.0;
  const Vec3 m = q - a0;
  const Vec3 mp = m - dot(m, w) * w;        // ray point at sigma = 0, radial part
  const Vec3 vp = v - dot(v, w) * w;        // direction, radial part; |vp| = sin(theta)
  const double k2 = dot(vp, vp);
  // Rays (almost) exactly parallel to the axis: the radial distance is constant
  // to within rounding over the whole interval; no division by sin(theta).
  const double span = std::max(std::abs(lo), std::abs(hi));
  if (k2 * span * span <= 1e-32 * std::max(dot(mp, mp), 1e-300) || k2 < 1e-200) {
    const double rho2 = dot(mp, mp);
    if (!(rho2 < 1.0)) return 0.0;
    const double f = (*pb.density)(std::sqrt(rho2));
    if (at.on()) {  // f times the attenuation's integral over [lo, hi]
      quad::Options opt;
      opt.rel_tol = rel_tol;
      const double pts[2] = {lo, hi};
      return f * quad::integrate_pieces([&at](double s) { return at.at(s); }, pts, 2, opt).value;
    }
    return (hi - lo) * f;
  }
  const double sc = -dot(mp, vp) / k2;  // closest approach to the axis line
  const Vec3 perp = mp + sc * vp;
  const double d2 = dot(perp, perp);
  if (!(d2 < 1.0)) return 0.0;
  const double inv_k = 1.0 / std::sqrt(k2);
  const double d = std::sqrt(d2);
  const double c = std::sqrt((1.0 - d) * (1.0 + d)) * inv_k;
  return integrate_radial(pb, d2, k2, inv_k, sc, std::max(lo, sc - c), std::min(hi, sc + c),
                          rel_tol, at);
}

// The point and line regions of one ray q + sigma v, for the kinds'
// reference_energy (protocol/beams/beam_base.hpp).
class RayIntegrals final : public RadialIntegrals {
 public:
  RayIntegrals(const PreparedBeam& pb, const Vec3& q, const Vec3& v, double rel_tol,
               const Attenuation& at)
      : pb_(pb), q_(q), v_(v), rel_tol_(rel_tol), at_(at) {}
  double point(const Vec3& a, double lo, double hi) const override {
    return integrate_point(pb_, q_, v_, a, lo, hi, rel_tol_, at_);
  }
  double line(const Vec3& a, const Vec3& w, double lo, double hi) const override {
    return integrate_line(pb_, q_, v_, a, w, lo, hi, rel_tol_, at_);
  }

 private:
  const PreparedBeam& pb_;
  const Vec3& q_;
  const Vec3& v_;
  double rel_tol_;
  Attenuation at_;
};

// (1/r) * integral of f e^(-optical depth from o) along o + t v, t in
// [t0, t1], |v| = 1 (no medium: null field).
double beam_energy_prepared(const PreparedBeam& pb, const Vec3& o, const Vec3& v, double t0,
                            double t1, double rel_tol, const MediumField* medium = nullptr) {
  if (!(t1 > t0)) return 0.0;
  const Vec3 oc = o - pb.c;
  const double t_ref = -dot(oc, v);
  const Vec3 q = pb.inv_r * (oc + t_ref * v);
  const double q2 = dot(q, q);
  if (!(q2 < pb.bound2)) return 0.0;  // misses the bounding sphere
  const double h = std::sqrt(pb.bound2 - q2);
  const double s0 = std::max((t0 - t_ref) * pb.inv_r, -h);
  const double s1 = std::min((t1 - t_ref) * pb.inv_r, h);
  if (!(s1 > s0)) return 0.0;

  const RayIntegrals f(pb, q, v, rel_tol, Attenuation{medium, o, v, t_ref, pb.r});
  return std::visit(
      [&](const auto& shape) { return shape.reference_energy(f, q, v, s0, s1, pb.r); },
      *pb.shape);
}

// ---------------------------------------------------------------------------
// Occluders

struct Hit {
  double t = kInf;
  Vec3 n{};                       // unit geometric normal, not yet oriented
  const Color* albedo = nullptr;  // null: no hit
};

// The nearest occluder hit of a ray with t in [t_min, t_max], if any; each
// kind intersects itself (protocol/occluders/).
// ---------------------------------------------------------------------------
// Scalar volumes

// A volume's default reference step: a sixteenth of its smallest spacing.
double default_volume_step(const Volume& v) {
  return std::min({v.spacing[0], v.spacing[1], v.spacing[2]}) / 16.0;
}

// The normalized value at a world point inside the volume's box.
double volume_value(const Volume& v, const Vec3& p, bool exact) {
  const Vec3 g = v.to_grid(p);
  return exact ? v.exact(g) : v.sample(g);
}

// The opacity of a segment of length `len` whose value is `value`.
double segment_alpha(const Volume& v, double value, double len) {
  const double op = v.transfer.opacity(value);
  if (op >= 1.0) return 1.0;
  return 1.0 - std::pow(1.0 - op, len / v.transfer.opacity_unit);
}

struct VolumeOnRay {
  const Volume* volume;
  double t0, t1, step;
};

}  // namespace

bool volume_interval(const Volume& volume, const Vec3& origin, const Vec3& dir, double t_min,
                     double t_max, double* t0, double* t1) {
  // In grid coordinates the box is [0, n - 1]^3 and the ray's parameter is
  // still the world distance (the map is affine).
  const Vec3 og = volume.to_grid(origin);
  const Vec3 dg = volume.to_grid(origin + dir) - og;
  double lo = t_min, hi = t_max;
  for (int a = 0; a < 3; ++a) {
    const double top = volume.grid->dims[a] - 1;
    if (std::abs(dg[a]) < 1e-300) {
      if (og[a] < 0.0 || og[a] > top) return false;
      continue;
    }
    const double ta = -og[a] / dg[a], tb = (top - og[a]) / dg[a];
    lo = std::max(lo, std::min(ta, tb));
    hi = std::min(hi, std::max(ta, tb));
  }
  *t0 = lo;
  *t1 = hi;
  return hi > lo;
}

VolumeComposite volume_composite_reference(const Volume& volume, const Vec3& origin, const Vec3& dir,
                                           double t0, double t1, double step, bool exact) {
  VolumeComposite out;
  double a = 0.0, b = 0.0;
  if (!(step > 0.0) || !volume_interval(volume, origin, dir, t0, t1, &a, &b)) return out;
  for (double s = a; s < b && out.transmittance > 0.0; s += step) {
    const double len = std::min(step, b - s);
    const double value = volume_value(volume, origin + (s + 0.5 * len) * dir, exact);
    const double alpha = segment_alpha(volume, value, len);
    const Color c = volume.transfer.color(value);
    for (int k = 0; k < 3; ++k) out.color[k] += out.transmittance * alpha * c[k] * volume.intensity;
    out.transmittance *= 1.0 - alpha;
  }
  return out;
}

namespace {

Hit nearest_hit(const Scene& scene, const Vec3& o, const Vec3& v, double t_min, double t_max) {
  Hit best;
  for (const Occluder& occ : scene.occluders) {
    const std::optional<OccluderHit> h = std::visit(
        [&](const auto& shape) { return shape.intersect(o, v, t_min, std::min(t_max, best.t)); },
        occ.shape);
    if (h) best = {h->t, h->n, &occ.albedo};
  }
  return best;
}

}  // namespace

double beam_energy_reference(const Beam& beam, const Vec3& origin, const Vec3& dir, double t0,
                             double t1, double rel_tol, double sigma_t) {
  if (!(t1 > t0) || !(beam.radius > 0.0)) return 0.0;
  const double len = length(dir);
  if (!(len > 0.0)) return 0.0;
  const PreparedBeam pb = prepare_beam(beam);
  // The integral is over the parameter t; with a non-unit direction the world
  // distance is t * |dir|, hence the rescaling.
  const Medium m{.sigma_a = sigma_t};
  const std::vector<MediumRegion> none;
  const MediumField field(&m, none);
  return beam_energy_prepared(pb, origin, (1.0 / len) * dir, t0 * len, t1 * len, rel_tol,
                              sigma_t > 0.0 ? &field : nullptr) /
         len;
}

namespace {

// A beam's energy along [t_min, t_end] with each point's light attenuated by
// the volumes in front of it: the ray is cut into the volumes' steps (the
// finest of them over their union), each piece's beam energy weighted by the
// transmittance at its middle (the volumes' opacity up to the piece's start,
// then half its own step's, exact for a piece of constant extinction).
double beam_energy_through_volumes(const PreparedBeam& pb, const Vec3& o, const Vec3& v,
                                   double t_min, double t_end, const std::vector<VolumeOnRay>& vols,
                                   const ReferenceOptions& opts, const MediumField* field) {
  double a = kInf, b = -kInf, step = kInf;
  for (const VolumeOnRay& vr : vols) {
    a = std::min(a, vr.t0);
    b = std::max(b, vr.t1);
    step = std::min(step, vr.step);
  }
  double energy = beam_energy_prepared(pb, o, v, t_min, a, opts.rel_tol, field);
  double transmittance = 1.0;
  for (double s = a; s < b && transmittance > 0.0; s += step) {
    const double len = std::min(step, b - s);
    const Vec3 mid = o + (s + 0.5 * len) * v;
    double pass = 1.0;  // what this piece lets through
    for (const VolumeOnRay& vr : vols) {
      if (s + 0.5 * len < vr.t0 || s + 0.5 * len > vr.t1) continue;
      pass *= 1.0 - segment_alpha(*vr.volume, volume_value(*vr.volume, mid, opts.volume_exact), len);
    }
    energy += transmittance * std::sqrt(pass) *
              beam_energy_prepared(pb, o, v, s, s + len, opts.rel_tol, field);
    transmittance *= pass;
  }
  if (transmittance > 0.0) {
    energy += transmittance * beam_energy_prepared(pb, o, v, b, t_end, opts.rel_tol, field);
  }
  return energy;
}

}  // namespace

HdrImage render_reference(const Scene& scene, const Camera& cam, const ReferenceOptions& opts) {
  HdrImage img;
  img.width = cam.width;
  img.height = cam.height;
  img.rgb.assign(3 * static_cast<std::size_t>(std::max(cam.width, 0)) * std::max(cam.height, 0),
                 0.0f);
  if (cam.width <= 0 || cam.height <= 0) return img;

  const CameraBasis basis = camera_basis(cam);
  std::vector<PreparedBeam> beams;
  std::vector<const Beam*> beam_src;
  for (const Beam& b : scene.beams) {
    if (!(b.radius > 0.0)) continue;
    beams.push_back(prepare_beam(b));
    beam_src.push_back(&b);
  }

  const MediumField medium = scene.medium_field();
  const MediumField* field = scene.has_medium() ? &medium : nullptr;
  const DirectionalLight& light = scene.light;
  const double llen = length(light.direction);
  const Vec3 to_light = llen > 0.0 ? (-1.0 / llen) * light.direction : Vec3{0.0, 0.0, 0.0};

  // Lit scenes: the surfaces' radiance from the path tracer, per pixel.
  std::optional<GiScene> gi;
  std::vector<Color> gi_radiance;
  const int total_rows = (scene.has_gi() ? 2 : 1) * cam.height;
  std::atomic<int> rows_done{0};
  const auto row_done = [&] {
    if (opts.on_progress) opts.on_progress(rows_done.fetch_add(1) + 1, total_rows);
  };
  if (scene.has_gi()) {
    gi.emplace(scene);
    PathTraceOptions po;
    po.spp = opts.gi_spp;
    po.seed = opts.gi_seed;
    po.threads = opts.threads;
    po.max_depth = opts.gi_max_depth;
    if (opts.on_progress) po.on_row = row_done;
    gi_radiance = path_trace(*gi, cam, po);
  }

  auto shade_row = [&](int y) {
    const int py = cam.height - 1 - y;  // GL pixel rows count from the bottom
    for (int x = 0; x < cam.width; ++x) {
      const Ray ray = camera_ray(cam, basis, x, py);
      const Hit hit = nearest_hit(scene, ray.origin, ray.dir, ray.t_min, ray.t_max);
      Color c = scene.background;
      double t_end = ray.t_max;
      bool surface = hit.albedo != nullptr;
      if (gi) {
        // Beams end at the surface or light the path tracer sees through the centre.
        const auto h = gi->intersect(ray.origin, ray.dir, ray.t_min, ray.t_max);
        if (h) t_end = h->t;
        surface = h.has_value();
        c = gi_radiance[static_cast<std::size_t>(y) * cam.width + x];
      } else if (hit.albedo) {
        t_end = hit.t;
        Vec3 n = hit.n;
        if (dot(n, ray.dir) > 0.0) n = -1.0 * n;  // two-sided
        const double lambert = light.ambient + light.intensity * std::max(0.0, dot(n, to_light));
        for (int k = 0; k < 3; ++k) c[k] = (*hit.albedo)[k] * light.color[k] * lambert;
      }
      if (field && !gi) {
        // The surface (or the background, at infinity) attenuated by the
        // optical depth to it (the path tracer follows lit scenes' paths
        // through the medium itself).
        const double tau = surface ? field->optical_depth(ray.origin, ray.dir, 0.0, t_end)
                                   : field->optical_depth(ray.origin, ray.dir, 0.0, kInf);
        const double tr = std::exp(-tau);
        for (int k = 0; k < 3; ++k) c[k] *= tr;
      }
      // The volumes this ray meets before its end.
      std::vector<VolumeOnRay> on_ray;
      for (const Volume& v : scene.volumes) {
        double a = 0.0, b = 0.0;
        if (volume_interval(v, ray.origin, ray.dir, ray.t_min, t_end, &a, &b)) {
          on_ray.push_back({&v, a, b, opts.volume_step > 0.0 ? opts.volume_step : default_volume_step(v)});
        }
      }
      // What lies behind the volumes, then each volume over it, farthest first.
      std::sort(on_ray.begin(), on_ray.end(),
                [](const VolumeOnRay& p, const VolumeOnRay& q) { return p.t1 > q.t1; });
      for (const VolumeOnRay& v : on_ray) {
        const VolumeComposite vc =
            volume_composite_reference(*v.volume, ray.origin, ray.dir, v.t0, v.t1, v.step,
                                       opts.volume_exact);
        for (int k = 0; k < 3; ++k) c[k] = vc.color[k] + vc.transmittance * c[k];
      }
      for (std::size_t b = 0; b < beams.size(); ++b) {
        const Beam& src = *beam_src[b];
        const double e = on_ray.empty()
                             ? beam_energy_prepared(beams[b], ray.origin, ray.dir, ray.t_min, t_end,
                                                    opts.rel_tol, field)
                             : beam_energy_through_volumes(beams[b], ray.origin, ray.dir, ray.t_min,
                                                           t_end, on_ray, opts, field);
        if (e == 0.0) continue;
        for (int k = 0; k < 3; ++k) c[k] += src.color[k] * src.intensity * e;
      }
      float* px = img.at(x, y);
      for (int k = 0; k < 3; ++k) px[k] = static_cast<float>(c[k]);
    }
    row_done();
  };

  parallel_items(cam.height, opts.threads, shade_row);
  return img;
}

}  // namespace beamcast
