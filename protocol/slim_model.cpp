#include "protocol/slim_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "protocol/check.hpp"

namespace beamcast {

namespace {

std::array<double, 4> conjugate(const std::array<double, 4>& q) { return {q[0], -q[1], -q[2], -q[3]}; }

// Entry and exit of the ray o + t v (v unit) through a sphere; false on a miss.
bool ray_sphere(const Vec3& o, const Vec3& v, const Vec3& c, double r, double* t0, double* t1) {
  const Vec3 e = c - o;
  const double tc = dot(e, v);
  const Vec3 perp = e - tc * v;
  const double d2 = dot(perp, perp);
  if (!(d2 < r * r)) return false;
  const double h = std::sqrt(r * r - d2);
  *t0 = tc - h;
  *t1 = tc + h;
  return true;
}

bool segment_box(const Vec3& o, const Vec3& v, const Aabb& b, double t0, double t1) {
  for (int k = 0; k < 3; ++k) {
    const double inv = 1.0 / v[k];
    double a = (b.lo[k] - o[k]) * inv, c = (b.hi[k] - o[k]) * inv;
    if (a > c) std::swap(a, c);
    // NaN (0 * inf: the ray in the slab's plane) keeps the interval.
    if (a > t0) t0 = a;
    if (c < t1) t1 = c;
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace

std::string_view crease_name(SlimCrease c) {
  switch (c) {
    case SlimCrease::kNone: return "none";
    case SlimCrease::kMin: return "min";
    case SlimCrease::kMax: return "max";
  }
  return "none";
}

double SlimSphere::height(double u, double v) const {
  const double a = poly.eval(u, v);
  switch (crease) {
    case SlimCrease::kNone: return a;
    case SlimCrease::kMin: return std::min(a, poly2.eval(u, v));
    case SlimCrease::kMax: return std::max(a, poly2.eval(u, v));
  }
  return a;
}

std::array<double, 2> SlimSphere::height_grad(double u, double v) const {
  if (crease == SlimCrease::kNone) return poly.grad(u, v);
  const double a = poly.eval(u, v), b = poly2.eval(u, v);
  const bool first = crease == SlimCrease::kMin ? a <= b : a >= b;
  return first ? poly.grad(u, v) : poly2.grad(u, v);
}

Vec3 SlimSphere::to_local(const Vec3& x) const { return rotate(conjugate(rotation), x - center); }
Vec3 SlimSphere::to_world(const Vec3& local) const { return center + rotate(rotation, local); }

Vec3 SlimSphere::surface_point(double u, double v) const { return to_world({u, v, height(u, v)}); }

Vec3 SlimSphere::surface_normal(double u, double v) const {
  const auto g = height_grad(u, v);
  return normalize(rotate(rotation, {-g[0], -g[1], 1.0}));
}

double slim_max_slope(const SlimSphere& s) {
  auto bound = [&](const SlimPoly& p) {
    const auto& c = p.c;
    const double du = (2.0 * std::abs(c[0]) + std::abs(c[1])) * s.radius + std::abs(c[3]);
    const double dv = (std::abs(c[1]) + 2.0 * std::abs(c[2])) * s.radius + std::abs(c[4]);
    return std::hypot(du, dv);
  };
  const double a = bound(s.poly);
  return s.crease == SlimCrease::kNone ? a : std::max(a, bound(s.poly2));
}

std::array<double, 2> slim_height_range(const SlimSphere& s) {
  // The patch's points on a G x G grid of (u, v) cell centres, h apart,
  // kept if within (1 + slope) h of the sphere: every point of the patch
  // inside the sphere has a grid point within h / 2 in u and in v, whose
  // point lies within (1 + slope) h of it and whose height differs by at
  // most slope x h; hence the pad.
  constexpr int kGrid = 32;
  const double r = s.radius;
  const double h = 2.0 * r / kGrid;
  const double slope = slim_max_slope(s);
  const double reach = r + (1.0 + slope) * h;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int i = 0; i < kGrid; ++i) {
    const double u = -r + (i + 0.5) * h;
    for (int j = 0; j < kGrid; ++j) {
      const double v = -r + (j + 0.5) * h;
      const double w = s.height(u, v);
      if (u * u + v * v + w * w > reach * reach) continue;
      lo = std::min(lo, w);
      hi = std::max(hi, w);
    }
  }
  if (!(lo <= hi)) return {-r, r};  // no grid point near: the whole sphere
  const double pad = slope * h + 1e-3 * r;
  return {std::clamp(lo - pad, -r, r), std::clamp(hi + pad, -r, r)};
}

Aabb slim_bounds(const std::vector<SlimSphere>& spheres) {
  Aabb b;
  for (const SlimSphere& s : spheres) {
    const Vec3 r{s.radius, s.radius, s.radius};
    b.grow(s.center - r);
    b.grow(s.center + r);
  }
  return b;
}

std::array<double, 4> quat_mul(const std::array<double, 4>& a, const std::array<double, 4>& b) {
  return {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
          a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
          a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
          a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
}

std::array<double, 4> quat_from_axes(const Vec3& x, const Vec3& y, const Vec3& z) {
  // Rotation matrix with columns x, y, z; Shepperd's method (largest pivot).
  const double m00 = x[0], m11 = y[1], m22 = z[2];
  const double trace = m00 + m11 + m22;
  std::array<double, 4> q;
  if (trace > 0.0) {
    const double s = 2.0 * std::sqrt(1.0 + trace);
    q = {0.25 * s, (y[2] - z[1]) / s, (z[0] - x[2]) / s, (x[1] - y[0]) / s};
  } else if (m00 > m11 && m00 > m22) {
    const double s = 2.0 * std::sqrt(1.0 + m00 - m11 - m22);
    q = {(y[2] - z[1]) / s, 0.25 * s, (y[0] + x[1]) / s, (z[0] + x[2]) / s};
  } else if (m11 > m22) {
    const double s = 2.0 * std::sqrt(1.0 + m11 - m00 - m22);
    q = {(z[0] - x[2]) / s, (y[0] + x[1]) / s, 0.25 * s, (z[1] + y[2]) / s};
  } else {
    const double s = 2.0 * std::sqrt(1.0 + m22 - m00 - m11);
    q = {(x[1] - y[0]) / s, (z[0] + x[2]) / s, (z[1] + y[2]) / s, 0.25 * s};
  }
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  return {q[0] / n, q[1] / n, q[2] / n, q[3] / n};
}

void transform_slim(std::vector<SlimSphere>& spheres, const Vec3& translate, double scale,
                    const std::array<double, 4>& rotation) {
  BEAMCAST_CHECK(scale > 0.0, "transform_slim needs a positive scale");
  for (SlimSphere& s : spheres) {
    s.center = translate + scale * rotate(rotation, s.center);
    s.radius *= scale;
    s.rotation = quat_mul(rotation, s.rotation);
    for (SlimPoly* p : {&s.poly, &s.poly2}) {
      for (int k = 0; k < 3; ++k) p->c[static_cast<std::size_t>(k)] /= scale;
      p->c[5] *= scale;
    }
  }
}

SlimField::SlimField(const std::vector<SlimSphere>* spheres) : spheres_(spheres) {
  order_.resize(spheres_->size());
  for (std::uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
  if (!order_.empty()) {
    nodes_.reserve(2 * order_.size());
    build(0, static_cast<std::uint32_t>(order_.size()));
  }
}

std::uint32_t SlimField::build(std::uint32_t first, std::uint32_t count) {
  const auto index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.emplace_back();
  Aabb box;
  for (std::uint32_t i = first; i < first + count; ++i) {
    const SlimSphere& s = (*spheres_)[order_[i]];
    const Vec3 r{s.radius, s.radius, s.radius};
    box.grow(s.center - r);
    box.grow(s.center + r);
  }
  nodes_[index].box = box;
  if (count <= 4) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  // Median split of the centres on the box's longest axis.
  const Vec3 ext = box.hi - box.lo;
  const int axis = ext[0] >= ext[1] && ext[0] >= ext[2] ? 0 : (ext[1] >= ext[2] ? 1 : 2);
  const std::uint32_t half = count / 2;
  std::nth_element(order_.begin() + first, order_.begin() + first + half,
                   order_.begin() + first + count, [&](std::uint32_t a, std::uint32_t b) {
                     return (*spheres_)[a].center[axis] < (*spheres_)[b].center[axis];
                   });
  const std::uint32_t left = build(first, half);
  const std::uint32_t right = build(first + half, count - half);
  nodes_[index].left = left;
  nodes_[index].right = right;
  return index;
}

template <class Visit>
void SlimField::visit_segment(const Vec3& o, const Vec3& v, double t0, double t1, Visit&& f) const {
  if (nodes_.empty()) return;
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (!segment_box(o, v, n.box, t0, t1)) continue;
    if (n.count > 0) {
      for (std::uint32_t i = n.first; i < n.first + n.count; ++i) f(order_[i]);
    } else {
      BEAMCAST_CHECK(top + 2 <= 128, "SlimField BVH deeper than its traversal stack");
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
  }
}

void SlimField::spheres_at(const Vec3& x, std::vector<std::uint32_t>& out) const {
  out.clear();
  const Vec3 dir{1.0, 0.0, 0.0};
  visit_segment(x, dir, 0.0, 0.0, [&](std::uint32_t i) {
    const SlimSphere& s = (*spheres_)[i];
    if (length(x - s.center) < s.radius) out.push_back(i);
  });
}

SlimField::Value SlimField::value_of(const Vec3& x,
                                     const std::vector<std::uint32_t>& candidates) const {
  Value out;
  double num = 0.0;
  for (std::uint32_t i : candidates) {
    const SlimSphere& s = (*spheres_)[i];
    const Vec3 d = x - s.center;
    const double w = slim_weight(length(d) / s.radius);
    if (w <= 0.0) continue;
    const Vec3 l = rotate(conjugate(s.rotation), d);
    num += w * (l[2] - s.height(l[0], l[1]));
    out.weight += w;
  }
  if (out.weight > 0.0) out.f = num / out.weight;
  return out;
}

SlimField::Value SlimField::value(const Vec3& x) const {
  std::vector<std::uint32_t> near;
  spheres_at(x, near);
  return value_of(x, near);
}

Vec3 SlimField::normal(const Vec3& x) const {
  std::vector<std::uint32_t> near;
  spheres_at(x, near);
  double r_min = std::numeric_limits<double>::infinity();
  for (std::uint32_t i : near) r_min = std::min(r_min, (*spheres_)[i].radius);
  if (near.empty()) return {0.0, 0.0, 1.0};
  // The spheres within reach of the stencil: near grown by the step.
  const double h = 1e-6 * r_min;
  std::vector<std::uint32_t> reach;
  visit_segment(x, Vec3{1.0, 0.0, 0.0}, -h, h, [&](std::uint32_t i) {
    const SlimSphere& s = (*spheres_)[i];
    if (length(x - s.center) < s.radius + 2.0 * h) reach.push_back(i);
  });
  Vec3 g{};
  for (int k = 0; k < 3; ++k) {
    Vec3 a = x, b = x;
    a[k] += h;
    b[k] -= h;
    g[k] = (value_of(a, reach).f - value_of(b, reach).f) / (2.0 * h);
  }
  return normalize(g);
}

std::optional<SlimField::Hit> SlimField::intersect(const Vec3& o, const Vec3& v, double t_min,
                                                   double t_max, double step_frac) const {
  struct Span {
    double t0, t1;
    std::uint32_t sphere;
  };
  std::vector<Span> spans;
  visit_segment(o, v, t_min, t_max, [&](std::uint32_t i) {
    const SlimSphere& s = (*spheres_)[i];
    double a, b;
    if (!ray_sphere(o, v, s.center, s.radius, &a, &b)) return;
    a = std::max(a, t_min);
    b = std::min(b, t_max);
    if (a < b) spans.push_back({a, b, i});
  });
  if (spans.empty()) return std::nullopt;
  std::sort(spans.begin(), spans.end(), [](const Span& x, const Span& y) { return x.t0 < y.t0; });

  std::vector<std::uint32_t> component, active;
  std::vector<double> breaks;
  std::size_t next = 0;
  while (next < spans.size()) {
    // One maximal interval [lo, hi] the supports cover without a gap.
    double hi = spans[next].t1;
    std::size_t end = next;
    while (end < spans.size() && spans[end].t0 < hi) {
      hi = std::max(hi, spans[end].t1);
      ++end;
    }
    component.clear();
    breaks.clear();
    for (std::size_t k = next; k < end; ++k) {
      component.push_back(spans[k].sphere);
      breaks.push_back(spans[k].t0);
      breaks.push_back(spans[k].t1);
    }
    std::sort(breaks.begin(), breaks.end());
    breaks.erase(std::unique(breaks.begin(), breaks.end()), breaks.end());

    auto eval = [&](double t, const std::vector<std::uint32_t>& set) {
      return value_of(o + t * v, set);
    };
    bool have_prev = false;
    double t_prev = 0.0, g_prev = 0.0;
    for (std::size_t b = 0; b + 1 < breaks.size(); ++b) {
      const double a0 = breaks[b], a1 = breaks[b + 1];
      const double mid = 0.5 * (a0 + a1);
      active.clear();
      double r_min = std::numeric_limits<double>::infinity();
      for (std::size_t k = next; k < end; ++k) {
        if (spans[k].t0 <= mid && spans[k].t1 >= mid) {
          active.push_back(spans[k].sphere);
          r_min = std::min(r_min, (*spheres_)[spans[k].sphere].radius);
        }
      }
      if (active.empty()) continue;
      const int n = std::max(1, static_cast<int>(std::ceil((a1 - a0) / (step_frac * r_min))));
      for (int k = (b == 0 ? 1 : 0); k <= n; ++k) {
        const double t = a0 + (a1 - a0) * k / n;
        const Value val = eval(t, active);
        if (!(val.weight > 1e-300)) continue;
        if (have_prev && (val.f == 0.0 || (val.f < 0.0) != (g_prev < 0.0))) {
          // Bracketed in [t_prev, t]: bisection over the component's spheres.
          double lo_t = t_prev, hi_t = t, g_lo = g_prev;
          const double tol = 1e-12 * r_min;
          for (int it = 0; it < 200 && hi_t - lo_t > tol; ++it) {
            const double m = 0.5 * (lo_t + hi_t);
            const Value vm = eval(m, component);
            if (vm.weight > 0.0 && (vm.f < 0.0) == (g_lo < 0.0) && vm.f != 0.0) {
              lo_t = m;
              g_lo = vm.f;
            } else {
              hi_t = m;
            }
          }
          const double th = 0.5 * (lo_t + hi_t);
          return Hit{th, normal(o + th * v)};
        }
        have_prev = true;
        t_prev = t;
        g_prev = val.f;
      }
    }
    next = end;
  }
  return std::nullopt;
}

}  // namespace beamcast
