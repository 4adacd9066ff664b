#include "slim/fit.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "slim/local_fit.hpp"

namespace beamcast::slim {

namespace {

// Points on the mesh that the local fits see: every vertex (normal: the
// area-weighted mean of its triangles') and samples on each triangle, as many
// as its share of the area asks for (at least its centroid), each with the
// triangle's normal. `area` is the share of surface a point stands for.
std::vector<FitPoint> sample_points(const TriangleMesh& mesh, std::int64_t target) {
  std::vector<Vec3> vn(mesh.vertices.size(), Vec3{0.0, 0.0, 0.0});
  std::vector<double> va(mesh.vertices.size(), 0.0);
  double total = 0.0;
  for (const auto& t : mesh.triangles) {
    const Vec3 c =
        cross(mesh.vertices[t[1]] - mesh.vertices[t[0]], mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    total += 0.5 * length(c);
  }
  if (!(total > 0.0) || !std::isfinite(total)) {
    throw std::invalid_argument("the mesh has no area to fit");
  }
  std::vector<FitPoint> out;
  out.reserve(static_cast<std::size_t>(target) + mesh.vertices.size() + mesh.triangles.size());
  // R2 low-discrepancy offsets (plastic number): evenly spread, deterministic.
  constexpr double kA1 = 0.7548776662466927, kA2 = 0.5698402909980532;
  for (const auto& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
    const Vec3 cr = cross(b - a, c - a);
    const double area = 0.5 * length(cr);
    if (!(area > 0.0)) continue;
    const Vec3 n = (1.0 / (2.0 * area)) * cr;
    for (int k = 0; k < 3; ++k) {
      vn[t[static_cast<std::size_t>(k)]] = vn[t[static_cast<std::size_t>(k)]] + cr;
      va[t[static_cast<std::size_t>(k)]] += area / 3.0;
    }
    const auto count =
        std::max<std::int64_t>(1, std::llround(static_cast<double>(target) * area / total));
    for (std::int64_t k = 0; k < count; ++k) {
      double s = std::fmod(1.0 / 3.0 + static_cast<double>(k) * kA1, 1.0);
      double r = std::fmod(1.0 / 3.0 + static_cast<double>(k) * kA2, 1.0);
      if (s + r > 1.0) {
        s = 1.0 - s;
        r = 1.0 - r;
      }
      out.push_back({a + s * (b - a) + r * (c - a), n, area / static_cast<double>(count)});
    }
  }
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    if (va[i] > 0.0 && length(vn[i]) > 0.0)
      out.push_back({mesh.vertices[i], normalize(vn[i]), va[i]});
  }
  return out;
}

class Fitter {
 public:
  Fitter(const std::vector<FitPoint>& pts, const FitOptions& opt, double error_world,
         FitResult* out)
      : pts_(pts), opt_(opt), error_(error_world), out_(out) {}

  // `parent_ball`: the points inside the parent's sphere (radius
  // `room` around this cell's centre fits inside it).
  void cell(const Vec3& lo, double side, int depth, const std::vector<std::uint32_t>& cell_pts,
            const std::vector<std::uint32_t>& parent_ball, double room) {
    const Vec3 c = lo + Vec3{0.5 * side, 0.5 * side, 0.5 * side};
    double r = opt_.support * side * std::numbers::sqrt3;
    std::vector<std::uint32_t> ball;
    auto gather = [&] {
      ball.clear();
      for (std::uint32_t i : parent_ball) {
        if (length(pts_[i].p - c) < r) ball.push_back(i);
      }
    };
    gather();
    // Too few points for a stable quadratic: grow the sphere, within the
    // parent's (its points are all this sphere can see, and the error check
    // must see every point the sphere covers).
    for (int g = 0; g < 6 && ball.size() < static_cast<std::size_t>(opt_.min_points) &&
                    ball.size() < parent_ball.size() && r < room;
         ++g) {
      r = std::min(1.25 * r, room);
      gather();
    }
    if (ball.size() < 6) return;  // nothing to fit; neighbours' spheres cover these points
    out_->depth = std::max(out_->depth, depth);

    const LocalFitSettings s{opt_.max_normal_deg, opt_.crease_deg};
    LocalFit best = fit_single(pts_, ball, c, r, s, false);
    if (best.ok && best.error <= error_) return keep(best);
    const LocalFit crease = fit_crease(pts_, ball, c, r, s);
    if (crease.ok && crease.error <= error_) return keep(crease);
    if (crease.ok && (!best.ok || crease.error < best.error)) best = crease;

    if (depth < opt_.max_depth && ball.size() >= 2 * static_cast<std::size_t>(opt_.min_points)) {
      split(lo, side, depth, cell_pts, ball, c, r);
      return;
    }
    // At the bottom: the best fit found, else one in the mean normal's frame
    // whatever the normals' spread.
    if (!best.ok) best = fit_single(pts_, ball, c, r, s, true);
    if (!best.ok) return;
    if (best.error > error_) ++out_->forced;
    keep(best);
  }

 private:
  void keep(const LocalFit& f) {
    out_->spheres.push_back(f.sphere);
    if (f.sphere.crease != SlimCrease::kNone) ++out_->creases;
  }

  void split(const Vec3& lo, double side, int depth, const std::vector<std::uint32_t>& cell_pts,
             const std::vector<std::uint32_t>& ball, const Vec3& c, double r) {
    const double h = 0.5 * side;
    const Vec3 mid = lo + Vec3{h, h, h};
    std::array<std::vector<std::uint32_t>, 8> child;
    for (std::uint32_t i : cell_pts) {
      const Vec3& p = pts_[i].p;
      const int k = (p[0] >= mid[0] ? 1 : 0) | (p[1] >= mid[1] ? 2 : 0) | (p[2] >= mid[2] ? 4 : 0);
      child[static_cast<std::size_t>(k)].push_back(i);
    }
    for (int k = 0; k < 8; ++k) {
      if (child[static_cast<std::size_t>(k)].empty()) continue;
      const Vec3 clo{lo[0] + ((k & 1) ? h : 0.0), lo[1] + ((k & 2) ? h : 0.0),
                     lo[2] + ((k & 4) ? h : 0.0)};
      const Vec3 cc = clo + Vec3{0.5 * h, 0.5 * h, 0.5 * h};
      cell(clo, h, depth + 1, child[static_cast<std::size_t>(k)], ball, r - length(cc - c));
    }
  }

  const std::vector<FitPoint>& pts_;
  const FitOptions& opt_;
  double error_;
  FitResult* out_;
};

}  // namespace

double model_size(const TriangleMesh& mesh) {
  const Aabb b = mesh.bounds();
  return b.empty() ? 0.0 : length(b.hi - b.lo);
}

FitResult fit_slim(const TriangleMesh& mesh, const FitOptions& o) {
  if (!(o.error > 0.0)) throw std::invalid_argument("--error must be positive");
  if (o.max_depth < 0 || o.max_depth > 20)
    throw std::invalid_argument("--max-depth must be in [0, 20]");
  if (o.min_points < 6) throw std::invalid_argument("min_points must be at least 6");
  if (!(o.support >= 0.5 && o.support <= 2.0))
    throw std::invalid_argument("support must be in [0.5, 2]");
  const auto t0 = std::chrono::steady_clock::now();
  const double size = model_size(mesh);
  if (!(size > 0.0) || !std::isfinite(size)) throw std::invalid_argument("the mesh has no extent");

  FitResult result;
  const std::int64_t target =
      o.fit_points > 0
          ? o.fit_points
          : std::max<std::int64_t>(4 * static_cast<std::int64_t>(mesh.triangles.size()), 400000);
  const std::vector<FitPoint> pts = sample_points(mesh, target);
  result.points = static_cast<std::int64_t>(pts.size());

  // The root cell: the bounding box's cube, a hair larger so no point sits on its faces.
  const Aabb box = mesh.bounds();
  const Vec3 ext = box.hi - box.lo;
  const double side = 1.001 * std::max({ext[0], ext[1], ext[2]});
  const Vec3 lo = box.centre() - Vec3{0.5 * side, 0.5 * side, 0.5 * side};
  std::vector<std::uint32_t> all(pts.size());
  for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  Fitter fitter(pts, o, o.error * size / 10.0, &result);
  fitter.cell(lo, side, 0, all, all, std::numeric_limits<double>::infinity());
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace beamcast::slim
