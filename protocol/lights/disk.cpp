#include "protocol/lights/disk.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "protocol/lights/light_parse.hpp"
#include "protocol/lights/sampling.hpp"

namespace beamcast {

using namespace json_read;

namespace {

constexpr double kPi = std::numbers::pi;

// Shirley and Chiu's concentric map of [0, 1)^2 onto the unit disk: area
// preserving (up to the factor pi / 4), so a uniform square point is uniform
// over the disk and a grid's equal cells map to equal, compact cells.
std::array<double, 2> concentric(double x, double y) {
  const double a = 2.0 * x - 1.0, b = 2.0 * y - 1.0;
  if (a == 0.0 && b == 0.0) return {0.0, 0.0};
  double r, phi;
  if (std::abs(a) > std::abs(b)) {
    r = a;
    phi = (kPi / 4.0) * (b / a);
  } else {
    r = b;
    phi = (kPi / 2.0) - (kPi / 4.0) * (a / b);
  }
  return {r * std::cos(phi), r * std::sin(phi)};
}

}  // namespace

DiskLight DiskLight::make(const Vec3& center, const Vec3& normal, double radius) {
  DiskLight d;
  d.center = center;
  d.normal = normalize(normal);
  d.radius = radius;
  orthonormal_basis(d.normal, &d.t, &d.b);
  d.area = kPi * radius * radius;
  return d;
}

DiskLight DiskLight::parse(const LightParse& in) {
  const Vec3 c = read_point(in.fields.required("center"), in.limits);
  // Any nonzero finite direction; its square normal (scale-free).
  const Vec3 n = read_direction(in.fields.required("normal"));
  // In [1e-15, max_abs_coordinate]: the area (>= 3e-30) and the GPU's float
  // outline stay normal numbers (issue 43).
  const double r = read_size(in.fields.required("radius"), in.limits);
  return make(c, n, r);
}

Aabb DiskLight::bounds() const {
  // Along axis i the disk reaches radius x sqrt(1 - normal_i^2) from its centre.
  Aabb box;
  Vec3 half{};
  for (std::size_t i = 0; i < 3; ++i) {
    half[i] = radius * std::sqrt(std::max(0.0, 1.0 - normal[i] * normal[i]));
  }
  box.grow(center - half);
  box.grow(center + half);
  return box;
}

Vec3 DiskLight::point(double x, double y) const {
  const auto [p, q] = concentric(x, y);
  return center + (radius * p) * t + (radius * q) * b;
}

Emission DiskLight::emit(const LightRandom& u) const {
  // Uniform in area, cosine-weighted in direction about the normal, as the
  // quad: each photon an equal share of a Lambertian emitter's flux.
  return {point(u[0], u[1]), cosine_hemisphere(normal, u[2], u[3]), 1.0};
}

LightSample DiskLight::sample(const Vec3& x, const LightRandom& u) const {
  const Vec3 y = point(u[0], u[1]);
  const Vec3 d = y - x;
  const double dist = length(d);
  if (!(dist > 0.0)) return {};
  const Vec3 dir = (1.0 / dist) * d;
  const double cos_y = -dot(dir, normal);
  if (cos_y <= 0.0) return {y, dir, dist, 0.0};
  // Radiance per unit flux 1 / (pi A), times cos_y / d^2, over the area pdf 1 / A.
  return {y, dir, dist, cos_y / (kPi * dist * dist)};
}

std::optional<double> DiskLight::hit(const Vec3& o, const Vec3& v, double t_max) const {
  // Seen only from the side it emits to; t > 0 strictly.
  const double denom = dot(v, normal);
  if (!(denom < 0.0)) return std::nullopt;
  const double t = dot(center - o, normal) / denom;
  if (!(t > 0.0 && t <= t_max)) return std::nullopt;
  // Within the radius, compared in units of the radius (no r^2 underflow).
  const Vec3 p = (1.0 / radius) * ((o + t * v) - center);
  if (!(dot(p, p) <= 1.0)) return std::nullopt;
  return t;
}

double DiskLight::radiance_scale() const { return 1.0 / (kPi * area); }

std::vector<DirectPoint> DiskLight::direct_points(int samples) const {
  // k x k cells of the square (k^2 close to `samples`), each the midpoint
  // rule's point of an equal share of the area: a cosine emitter of 1/k^2
  // of the radiance x area.
  const int n = std::max(1, samples);
  const int k = std::max(1, static_cast<int>(std::lround(std::sqrt(static_cast<double>(n)))));
  const Vec3 lift = (1e-5 * radius) * normal;  // as the quad: its shadow map sees its plane behind
  std::vector<DirectPoint> out;
  out.reserve(static_cast<std::size_t>(k) * static_cast<std::size_t>(k));
  for_each_cell_in_blocks(k, k, [&](int i, int j) {
    DirectPoint p;
    p.position = point((i + 0.5) / k, (j + 0.5) / k) + lift;
    p.axis = normal;
    p.mode = DirectPoint::Mode::kCosine;
    p.scale = 1.0 / (kPi * k * k);
    out.push_back(p);
  });
  return out;
}

std::optional<LightOutline> DiskLight::outline() const {
  // The square about the disk: corner - r t - r b, edges 2 r t and 2 r b
  // (cross(t, b) = normal), the disk inscribed.
  const Vec3 u = (2.0 * radius) * t, v = (2.0 * radius) * b;
  return LightOutline{kOutlineCode, center - 0.5 * u - 0.5 * v, u, v, normal};
}

void DiskLight::outline_triangles(TriangleSink& sink) const {
  // A fan about the centre, each triangle facing along the normal.
  Vec3 prev = center + radius * t;
  for (int i = 1; i <= kOutlineSides; ++i) {
    const double phi = 2.0 * kPi * i / kOutlineSides;
    const Vec3 next = i == kOutlineSides
                          ? center + radius * t
                          : center + (radius * std::cos(phi)) * t + (radius * std::sin(phi)) * b;
    sink.add(center, prev, next, true);
    prev = next;
  }
}

void DiskLight::cache_key(LightKey& k) const {
  k.put(center);
  k.put(normal);
  k.put(radius);
}

}  // namespace beamcast
