// The fit's error as SLIM papers report it: the first-order distance
// |F| / |grad F| from points on the mesh to the zero set of the blended
// function, at the model scaled to size 10 (bounding box diagonal).
#include <algorithm>
#include <cmath>
#include <random>

#include "slim/fit.hpp"

namespace beamcast::slim {

FitError measure_fit_error_at(const std::vector<Vec3>& points, double size,
                              const std::vector<SlimSphere>& spheres) {
  FitError out;
  out.samples = static_cast<std::int64_t>(points.size());
  const SlimField field(&spheres);
  const double to_unit = 10.0 / size;
  // Central differences over 1e-5 of the model: far below any support radius
  // a fit makes, far above double rounding of F.
  const double h = 1e-5 * size;
  double sum = 0.0, sum2 = 0.0;
  std::int64_t covered = 0;
  for (const Vec3& x : points) {
    const SlimField::Value v = field.value(x);
    if (!(v.weight > 0.0)) {
      ++out.uncovered;
      continue;
    }
    Vec3 g{};
    for (int k = 0; k < 3; ++k) {
      Vec3 a = x, b = x;
      a[k] += h;
      b[k] -= h;
      g[k] = (field.value(a).f - field.value(b).f) / (2.0 * h);
    }
    const double gl = length(g);
    // |grad F| ~ 1 where the field is sane; a vanishing gradient would
    // turn a tiny F into a huge distance, so it falls back to |F|.
    const double d = std::abs(v.f) / (gl > 1e-3 ? gl : 1.0) * to_unit;
    sum += d;
    sum2 += d * d;
    out.max = std::max(out.max, d);
    ++covered;
  }
  if (covered > 0) {
    out.mean = sum / static_cast<double>(covered);
    out.rms = std::sqrt(sum2 / static_cast<double>(covered));
  }
  return out;
}

FitError measure_fit_error(const TriangleMesh& mesh, const std::vector<SlimSphere>& spheres,
                           std::int64_t samples, std::uint32_t seed) {
  // Uniform by area: a triangle by its share of the cumulative area, then
  // uniform barycentric coordinates (the square-root map).
  std::vector<double> cum;
  cum.reserve(mesh.triangles.size());
  double total = 0.0;
  for (const auto& t : mesh.triangles) {
    total += 0.5 * length(cross(mesh.vertices[t[1]] - mesh.vertices[t[0]],
                                mesh.vertices[t[2]] - mesh.vertices[t[0]]));
    cum.push_back(total);
  }
  std::vector<Vec3> pts;
  if (total > 0.0) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    pts.reserve(static_cast<std::size_t>(samples));
    for (std::int64_t i = 0; i < samples; ++i) {
      const double pick = uni(rng) * total;
      const auto it = std::upper_bound(cum.begin(), cum.end(), pick);
      const auto& t = mesh.triangles[std::min<std::size_t>(
          static_cast<std::size_t>(it - cum.begin()), cum.size() - 1)];
      const double s = std::sqrt(uni(rng)), r = uni(rng);
      const Vec3 a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
      pts.push_back((1.0 - s) * a + (s * (1.0 - r)) * b + (s * r) * c);
    }
  }
  return measure_fit_error_at(pts, model_size(mesh), spheres);
}

}  // namespace beamcast::slim
