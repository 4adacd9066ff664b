#include "slim/local_fit.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace beamcast::slim {

namespace {

double deg(double cos_angle) {
  return std::acos(std::clamp(cos_angle, -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

struct Frame {
  Vec3 c;
  double r;
  Vec3 u, v, w;
  // Local coordinates divided by r: the fit runs on [-1, 1]^2, well conditioned at any scale.
  Vec3 local(const Vec3& x) const {
    const Vec3 d = (1.0 / r) * (x - c);
    return {dot(d, u), dot(d, v), dot(d, w)};
  }
};

Frame frame_of(const Vec3& c, double r, const Vec3& n) {
  const Vec3 a = std::abs(n[0]) < 0.9 ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
  const Vec3 u = normalize(cross(a, n));
  return {c, r, u, cross(n, u), n};
}

double weight_of(const FitPoint& p, const Frame& f) {
  return p.area * slim_weight(length(p.p - f.c) / f.r);
}

// Point-to-surface distance estimate in the normalized frame.
double distance(const SlimPoly& q, const Vec3& l) {
  const auto g = q.grad(l[0], l[1]);
  return std::abs(l[2] - q.eval(l[0], l[1])) / std::sqrt(1.0 + g[0] * g[0] + g[1] * g[1]);
}

double crease_distance(const SlimPoly& a, const SlimPoly& b, SlimCrease rule, const Vec3& l) {
  const double ha = a.eval(l[0], l[1]), hb = b.eval(l[0], l[1]);
  const bool first = rule == SlimCrease::kMin ? ha <= hb : ha >= hb;
  return distance(first ? a : b, l);
}

// The sphere in mesh coordinates: the normalized coefficients scaled back
// (w/r = A' (u/r)^2 + ... gives A = A'/r, D = D', F = F' r).
SlimPoly to_mesh_units(const SlimPoly& q, double r) {
  SlimPoly out = q;
  for (int k = 0; k < 3; ++k) out.c[static_cast<std::size_t>(k)] /= r;
  out.c[5] *= r;
  return out;
}

SlimSphere make_sphere(const Frame& f) {
  SlimSphere s;
  s.center = f.c;
  s.radius = f.r;
  s.rotation = quat_from_axes(f.u, f.v, f.w);
  return s;
}

// Weighted mean of the normals (unnormalized) and the widest angle from it.
Vec3 mean_normal(const std::vector<FitPoint>& pts, const std::vector<std::uint32_t>& ids,
                 const Vec3& c, double r) {
  Vec3 m{0.0, 0.0, 0.0};
  for (std::uint32_t i : ids)
    m = m + pts[i].area * slim_weight(length(pts[i].p - c) / r) * pts[i].n;
  return m;
}

double spread_deg(const std::vector<FitPoint>& pts, const std::vector<std::uint32_t>& ids,
                  const Vec3& mean_unit) {
  double worst = 1.0;
  for (std::uint32_t i : ids) worst = std::min(worst, dot(pts[i].n, mean_unit));
  return deg(worst);
}

}  // namespace

bool solve_quadratic(const std::vector<std::array<double, 4>>& samples, SlimPoly* out) {
  double m[6][6] = {}, rhs[6] = {};
  int used = 0;
  for (const auto& s : samples) {
    if (s[3] > 0.0) ++used;
    const double u = s[0], v = s[1], wt = s[3];
    const double phi[6] = {u * u, u * v, v * v, u, v, 1.0};
    for (int i = 0; i < 6; ++i) {
      rhs[i] += wt * phi[i] * s[2];
      for (int j = 0; j <= i; ++j) m[i][j] += wt * phi[i] * phi[j];
    }
  }
  if (used < 6) return false;  // fewer points than unknowns
  double trace = 0.0;
  for (int i = 0; i < 6; ++i) trace += m[i][i];
  if (!(trace > 0.0)) return false;
  for (int i = 0; i < 5; ++i) m[i][i] += 1e-9 * trace;
  // Cholesky M = L L^T in the lower triangle.
  double l[6][6] = {};
  for (int j = 0; j < 6; ++j) {
    double d = m[j][j];
    for (int k = 0; k < j; ++k) d -= l[j][k] * l[j][k];
    if (!(d > 1e-14 * trace)) return false;
    l[j][j] = std::sqrt(d);
    for (int i = j + 1; i < 6; ++i) {
      double s = m[i][j];
      for (int k = 0; k < j; ++k) s -= l[i][k] * l[j][k];
      l[i][j] = s / l[j][j];
    }
  }
  double y[6];
  for (int i = 0; i < 6; ++i) {
    double s = rhs[i];
    for (int k = 0; k < i; ++k) s -= l[i][k] * y[k];
    y[i] = s / l[i][i];
  }
  for (int i = 5; i >= 0; --i) {
    double s = y[i];
    for (int k = i + 1; k < 6; ++k) s -= l[k][i] * out->c[static_cast<std::size_t>(k)];
    out->c[static_cast<std::size_t>(i)] = s / l[i][i];
  }
  for (double c : out->c) {
    if (!std::isfinite(c)) return false;
  }
  return true;
}

LocalFit fit_single(const std::vector<FitPoint>& pts, const std::vector<std::uint32_t>& ball,
                    const Vec3& c, double r, const LocalFitSettings& s, bool force) {
  LocalFit out;
  Vec3 m = mean_normal(pts, ball, c, r);
  if (!(length(m) > 0.0)) {
    if (!force) return out;
    m = pts[ball.front()].n;  // normals cancel out: any frame will do for a forced fit
  }
  const Vec3 n = normalize(m);
  if (!force && spread_deg(pts, ball, n) > s.max_normal_deg) return out;
  const Frame f = frame_of(c, r, n);
  std::vector<std::array<double, 4>> samples;
  samples.reserve(ball.size());
  for (std::uint32_t i : ball) {
    const Vec3 l = f.local(pts[i].p);
    samples.push_back({l[0], l[1], l[2], weight_of(pts[i], f)});
  }
  SlimPoly q;
  if (!solve_quadratic(samples, &q)) return out;
  double worst = 0.0;
  for (const auto& smp : samples) worst = std::max(worst, distance(q, {smp[0], smp[1], smp[2]}));
  out.ok = true;
  out.sphere = make_sphere(f);
  out.sphere.poly = to_mesh_units(q, r);
  out.error = worst * r;
  return out;
}

LocalFit fit_crease(const std::vector<FitPoint>& pts, const std::vector<std::uint32_t>& ball,
                    const Vec3& c, double r, const LocalFitSettings& s) {
  LocalFit out;
  // 2-means on the normals, seeded by the normal farthest from the mean and
  // the normal farthest from that one.
  const Vec3 m = mean_normal(pts, ball, c, r);
  const Vec3 ref = length(m) > 0.0 ? normalize(m) : pts[ball.front()].n;
  std::uint32_t ia = ball.front();
  for (std::uint32_t i : ball) {
    if (dot(pts[i].n, ref) < dot(pts[ia].n, ref)) ia = i;
  }
  std::uint32_t ib = ball.front();
  for (std::uint32_t i : ball) {
    if (dot(pts[i].n, pts[ia].n) < dot(pts[ib].n, pts[ia].n)) ib = i;
  }
  Vec3 ca = pts[ia].n, cb = pts[ib].n;
  std::vector<std::uint32_t> ga, gb;
  for (int it = 0; it < 10; ++it) {
    ga.clear();
    gb.clear();
    for (std::uint32_t i : ball) (dot(pts[i].n, ca) >= dot(pts[i].n, cb) ? ga : gb).push_back(i);
    if (ga.size() < 6 || gb.size() < 6) return out;
    const Vec3 na = mean_normal(pts, ga, c, r), nb = mean_normal(pts, gb, c, r);
    if (!(length(na) > 0.0) || !(length(nb) > 0.0)) return out;
    const Vec3 na_u = normalize(na), nb_u = normalize(nb);
    const bool same = dot(na_u, ca) > 1.0 - 1e-12 && dot(nb_u, cb) > 1.0 - 1e-12;
    ca = na_u;
    cb = nb_u;
    if (same) break;
  }
  // A crease is two tight groups far apart: each group's spread under the
  // angle between them (a smoothly curved patch splits into groups about as
  // wide as their distance, and is left to the octree).
  const double between = deg(dot(ca, cb));
  if (between < s.crease_deg) return out;
  const double within = std::max(spread_deg(pts, ga, ca), spread_deg(pts, gb, cb));
  if (within > s.max_normal_deg || within > between) return out;
  // The bisector frame; both faces then lean at most (180 - angle) / 2 from it.
  const Vec3 bis = ca + cb;
  if (length(bis) < 0.5) return out;  // folded back on itself (over ~150 degrees)
  const Frame f = frame_of(c, r, normalize(bis));
  auto fit_group = [&](const std::vector<std::uint32_t>& g, SlimPoly* q) {
    std::vector<std::array<double, 4>> samples;
    samples.reserve(g.size());
    for (std::uint32_t i : g) {
      const Vec3 l = f.local(pts[i].p);
      samples.push_back({l[0], l[1], l[2], weight_of(pts[i], f)});
    }
    return solve_quadratic(samples, q);
  };
  SlimPoly qa, qb;
  if (!fit_group(ga, &qa) || !fit_group(gb, &qb)) return out;
  // Min or max: whichever reproduces the points better (weighted squares).
  std::vector<Vec3> local;
  local.reserve(ball.size());
  double e_min = 0.0, e_max = 0.0;
  for (std::uint32_t i : ball) {
    const Vec3 l = f.local(pts[i].p);
    local.push_back(l);
    const double wt = weight_of(pts[i], f);
    const double a = qa.eval(l[0], l[1]), b = qb.eval(l[0], l[1]);
    e_min += wt * std::pow(l[2] - std::min(a, b), 2);
    e_max += wt * std::pow(l[2] - std::max(a, b), 2);
  }
  const SlimCrease rule = e_min <= e_max ? SlimCrease::kMin : SlimCrease::kMax;
  double worst = 0.0;
  for (const Vec3& l : local) worst = std::max(worst, crease_distance(qa, qb, rule, l));
  out.ok = true;
  out.sphere = make_sphere(f);
  out.sphere.poly = to_mesh_units(qa, r);
  out.sphere.poly2 = to_mesh_units(qb, r);
  out.sphere.crease = rule;
  out.error = worst * r;
  return out;
}

}  // namespace beamcast::slim
