#include "protocol/lights/quad.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "protocol/lights/light_parse.hpp"
#include "protocol/lights/sampling.hpp"
#include "protocol/parallelogram.hpp"

namespace beamcast {

using namespace json_read;

QuadLight QuadLight::parse(const LightParse& in) {
  QuadLight q;
  const Parallelogram p = Parallelogram::read(in.fields, in.limits, "light");
  q.corner = p.corner;
  q.edge_u = p.edge_u;
  q.edge_v = p.edge_v;
  q.area = p.area();
  q.normal = p.unit_normal();
  return q;
}

Aabb QuadLight::bounds() const { return Parallelogram{corner, edge_u, edge_v}.bounds(); }

Emission QuadLight::emit(const LightRandom& u) const {
  // Uniform in area, cosine-weighted in direction: each photon carries an
  // equal share of a Lambertian emitter's flux.
  return {corner + u[0] * edge_u + u[1] * edge_v, cosine_hemisphere(normal, u[2], u[3]), 1.0};
}

LightSample QuadLight::sample(const Vec3& x, const LightRandom& u) const {
  const Vec3 y = corner + u[0] * edge_u + u[1] * edge_v;
  const Vec3 d = y - x;
  const double dist = length(d);
  if (!(dist > 0.0)) return {};
  const Vec3 dir = (1.0 / dist) * d;
  const double cos_y = -dot(dir, normal);
  if (cos_y <= 0.0) return {y, dir, dist, 0.0};
  // Radiance per unit flux 1 / (pi A), times cos_y / d^2, over the area pdf 1 / A.
  return {y, dir, dist, cos_y / (std::numbers::pi * dist * dist)};
}

std::optional<double> QuadLight::hit(const Vec3& o, const Vec3& v, double t_max) const {
  // Seen only from the side it emits to; t > 0 strictly.
  const auto t = Parallelogram{corner, edge_u, edge_v}.hit(o, v, 0.0, t_max, true);
  if (!t || !(*t > 0.0)) return std::nullopt;
  return t;
}

double QuadLight::radiance_scale() const { return 1.0 / (std::numbers::pi * area); }

std::optional<LightOutline> QuadLight::outline() const {
  return LightOutline{kOutlineCode, corner, edge_u, edge_v, normal};
}

void QuadLight::outline_triangles(TriangleSink& sink) const {
  const Vec3 far = corner + edge_u + edge_v;
  sink.add(corner, corner + edge_u, far, true);
  sink.add(corner, far, corner + edge_v, true);
}

void QuadLight::cache_key(LightKey& k) const {
  k.put(corner);
  k.put(edge_u);
  k.put(edge_v);
}

std::vector<DirectPoint> QuadLight::direct_points(int samples) const {
  // The centres of a k_u x k_v grid of equal cells (k_u k_v close to
  // `samples`, cells near square): the midpoint rule over the area, each
  // point a cosine emitter with 1/(k_u k_v) of the radiance x area.
  const double lu = length(edge_u), lv = length(edge_v);
  const int n = std::max(1, samples);
  const int ku = std::clamp(static_cast<int>(std::lround(std::sqrt(n * lu / lv))), 1, n);
  const int kv = std::max(1, static_cast<int>(std::lround(static_cast<double>(n) / ku)));
  // A hair in front of the emitting face, so a shadow map rendered from the
  // point sees the quad's own plane behind it.
  const Vec3 lift = (1e-5 * std::max(lu, lv)) * normal;
  std::vector<DirectPoint> out;
  out.reserve(static_cast<std::size_t>(ku) * static_cast<std::size_t>(kv));
  for_each_cell_in_blocks(ku, kv, [&](int i, int j) {
    DirectPoint p;
    p.position = corner + ((i + 0.5) / ku) * edge_u + ((j + 0.5) / kv) * edge_v + lift;
    p.axis = normal;
    p.mode = DirectPoint::Mode::kCosine;
    p.scale = 1.0 / (std::numbers::pi * ku * kv);
    out.push_back(p);
  });
  return out;
}

}  // namespace beamcast
