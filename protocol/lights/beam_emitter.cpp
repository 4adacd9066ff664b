#include "protocol/lights/beam_emitter.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <type_traits>

#include "protocol/lights/sampling.hpp"

namespace beamcast {

namespace {

constexpr double kPi = std::numbers::pi;

// Two uniform numbers from one: the high and low halves of its 52 bits of
// fraction (26 bits each), so four LightRandom numbers give eight.
void split(double u, double* a, double* b) {
  const double hi = std::floor(u * 67108864.0);  // 2^26
  *a = hi / 67108864.0;
  *b = std::clamp(u * 67108864.0 - hi, 0.0, std::nextafter(1.0, 0.0));
}

// 4-point Gauss-Legendre nodes and weights on [-1, 1].
constexpr std::array<double, 4> kGaussX{-0.8611363115940526, -0.3399810435848563,
                                        0.3399810435848563, 0.8611363115940526};
constexpr std::array<double, 4> kGaussW{0.3478548451374538, 0.6521451548625461,
                                        0.6521451548625461, 0.3478548451374538};

struct CapsuleParts {
  Vec3 axis{0.0, 0.0, 1.0};  // unit, p0 -> p1
  double length = 0.0;
  double cylinder = 0.0;     // mass of the cylinder part
  double cap = 0.0;          // mass of one half-ball
  int caps = 0;              // 0, 1 or 2 half-balls present
};

CapsuleParts parts(const CapsuleBeam& c, double r, const RadialMass& m) {
  CapsuleParts p;
  const Vec3 d = c.p1 - c.p0;
  p.length = length(d);
  if (p.length > 0.0) p.axis = (1.0 / p.length) * d;
  p.cylinder = 2.0 * kPi * r * r * p.length * m.s1;
  p.cap = 2.0 * kPi * r * r * r * m.s2;
  p.caps = (c.cap0 ? 1 : 0) + (c.cap1 ? 1 : 0);
  return p;
}

}  // namespace

RadialMass::RadialMass(const Density& f) : cdf1(kCells + 1, 0.0), cdf2(kCells + 1, 0.0) {
  const double h = 1.0 / kCells;
  for (int i = 0; i < kCells; ++i) {
    double m1 = 0.0, m2 = 0.0, m3 = 0.0;
    for (std::size_t g = 0; g < kGaussX.size(); ++g) {
      const double x = h * (i + 0.5 + 0.5 * kGaussX[g]);
      const double w = 0.5 * h * kGaussW[g] * f(x);
      m1 += w * x;
      m2 += w * x * x;
      m3 += w * x * x * x;
    }
    cdf1[i + 1] = cdf1[i] + m1;
    cdf2[i + 1] = cdf2[i] + m2;
    s3 += m3;
  }
  s1 = cdf1.back();
  s2 = cdf2.back();
  for (double& v : cdf1) v = s1 > 0.0 ? v / s1 : 0.0;
  for (double& v : cdf2) v = s2 > 0.0 ? v / s2 : 0.0;
}

double RadialMass::sample(int k, double u) const {
  const std::vector<double>& cdf = k == 1 ? cdf1 : cdf2;
  // The first cell end at or above u; linear within the cell.
  const auto it = std::lower_bound(cdf.begin() + 1, cdf.end(), u);
  const auto i = static_cast<std::size_t>(std::min<std::ptrdiff_t>(it - cdf.begin(), kCells)) - 1;
  const double span = cdf[i + 1] - cdf[i];
  const double a = span > 0.0 ? std::clamp((u - cdf[i]) / span, 0.0, 1.0) : 0.5;
  return (static_cast<double>(i) + a) / kCells;
}

BeamEmitter BeamEmitter::from_beam(const BeamShape& shape, double radius, const Density& density,
                                   int beam_index) {
  BeamEmitter e;
  e.shape = shape;
  e.radius = radius;
  e.mass = std::make_shared<const RadialMass>(density);
  e.density_key = density.key();
  e.beam = beam_index;
  return e;
}

double BeamEmitter::volume_mass() const {
  return std::visit(
      [&](const auto& kind) {
        using Kind = std::decay_t<decltype(kind)>;
        if constexpr (std::is_same_v<Kind, SphereBeam>) {
          return 4.0 * kPi * radius * radius * radius * mass->s2;
        } else {
          const CapsuleParts p = parts(kind, radius, *mass);
          return p.cylinder + p.caps * p.cap;
        }
      },
      shape);
}

Aabb BeamEmitter::bounds() const {
  Aabb b = std::visit([](const auto& kind) { return kind.defining_bounds(); }, shape);
  b.lo = b.lo - Vec3{radius, radius, radius};
  b.hi = b.hi + Vec3{radius, radius, radius};
  return b;
}

Vec3 BeamEmitter::sample_point(const LightRandom& u) const {
  double part = 0.0, ux = 0.0, ua = 0.0, ub = 0.0;
  split(u[0], &part, &ux);
  split(u[1], &ua, &ub);
  return std::visit(
      [&](const auto& kind) -> Vec3 {
        using Kind = std::decay_t<decltype(kind)>;
        if constexpr (std::is_same_v<Kind, SphereBeam>) {
          return kind.center + (radius * mass->sample(2, ux)) * uniform_sphere(ua, ub);
        } else {
          const CapsuleParts p = parts(kind, radius, *mass);
          const double total = p.cylinder + p.caps * p.cap;
          if (total > 0.0 && part * total < p.cylinder) {
            // The cylinder: along the axis uniformly, radially by f(x) x.
            const double phi = 2.0 * kPi * ub;
            const double x = radius * mass->sample(1, ux);
            return kind.p0 + (ua * p.length) * p.axis +
                   from_local(p.axis, x * std::cos(phi), x * std::sin(phi), 0.0);
          }
          // A half-ball: a point of the whole ball, moved to the cap on its side
          // (a missing cap sends its half to the other one: both halves are
          // equal, so the density stays right).
          const Vec3 off = (radius * mass->sample(2, ux)) * uniform_sphere(ua, ub);
          const bool at_p1 = p.caps == 2 ? dot(off, p.axis) >= 0.0 : kind.cap1;
          const double side = dot(off, p.axis);
          const Vec3 o = (at_p1 == (side >= 0.0)) ? off : off - (2.0 * side) * p.axis;
          return (at_p1 ? kind.p1 : kind.p0) + o;
        }
      },
      shape);
}

Emission BeamEmitter::emit(const LightRandom& u) const {
  double a = 0.0, b = 0.0;
  split(u[2], &a, &b);
  double c = 0.0, d = 0.0;
  split(u[3], &c, &d);
  return {sample_point(u), uniform_sphere(a, c), 1.0};
}

LightSample BeamEmitter::sample(const Vec3& x, const LightRandom& u) const {
  const Vec3 y = sample_point(u);
  const Vec3 d = y - x;
  const double dist = length(d);
  if (!(dist > 0.0)) return {};
  return {y, (1.0 / dist) * d, dist, 1.0 / (4.0 * kPi * dist * dist)};
}

std::optional<double> BeamEmitter::hit(const Vec3&, const Vec3&, double) const {
  return std::nullopt;  // rays see the glow through the beam pass, not as a surface
}

std::vector<DirectPoint> BeamEmitter::direct_points(int samples) const {
  const double iso = 1.0 / (4.0 * kPi);
  return std::visit(
      [&](const auto& kind) {
        using Kind = std::decay_t<decltype(kind)>;
        std::vector<DirectPoint> points;
        if constexpr (std::is_same_v<Kind, SphereBeam>) {
          DirectPoint p;
          p.position = kind.center;
          p.scale = iso;
          points.push_back(p);
        } else {
          const CapsuleParts p = parts(kind, radius, *mass);
          const double total = p.cylinder + p.caps * p.cap;
          if (!(total > 0.0)) return points;
          const int along = std::max(1, samples - p.caps);
          for (int i = 0; i < along; ++i) {
            DirectPoint q;
            q.position = kind.p0 + (p.length * (i + 0.5) / along) * p.axis;
            q.scale = iso * p.cylinder / total / along;
            points.push_back(q);
          }
          // A half-ball's centroid lies (r / 2) S3 / S2 beyond its end (the
          // mean of cos over a hemisphere is 1/2).
          const double c = mass->s2 > 0.0 ? 0.5 * radius * mass->s3 / mass->s2 : 0.0;
          for (int end = 0; end < 2; ++end) {
            if (!(end == 0 ? kind.cap0 : kind.cap1)) continue;
            DirectPoint q;
            q.position = end == 0 ? kind.p0 - c * p.axis : kind.p1 + c * p.axis;
            q.scale = iso * p.cap / total;
            points.push_back(q);
          }
        }
        return points;
      },
      shape);
}

void BeamEmitter::cache_key(LightKey& k) const {
  std::visit(
      [&](const auto& beam) {
        const BeamGpu g = beam.gpu(Vec3{0.0, 0.0, 0.0});
        k.put(g.p0);
        k.put(g.axis);
        k.put(g.length);
        k.put(g.caps_kind);
      },
      shape);
  k.put(radius);
  k.put(density_key.size());
  k.text(density_key);
}

}  // namespace beamcast
