#include "render/slim_compare.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <variant>

#include "gi/parallel.hpp"
#include "protocol/camera.hpp"
#include "protocol/occluders/slim.hpp"

namespace beamcast {

SlimPixels slim_reference(const Scene& scene, const Camera& cam, int threads, int samples) {
  SlimPixels out;
  out.width = cam.width;
  out.height = cam.height;
  const std::size_t n = static_cast<std::size_t>(cam.width) * cam.height;
  out.covered.assign(n, 0);
  out.depth.assign(n, 0.0f);
  out.normal.assign(n, Vec3{0.0, 0.0, 0.0});
  std::vector<const SlimOccluder*> slims;
  for (const Occluder& o : scene.occluders) {
    if (const auto* s = std::get_if<SlimOccluder>(&o.shape)) slims.push_back(s);
  }
  const CameraBasis basis = camera_basis(cam);
  // The nearest hit along a ray through window position (wx, wy).
  auto trace = [&](double wx, double wy, double* depth, Vec3* normal) {
    const Ray ray =
        camera_ray_ndc(cam, basis, 2.0 * wx / cam.width - 1.0, 2.0 * wy / cam.height - 1.0);
    double best = ray.t_max;
    std::optional<OccluderHit> hit;
    for (const SlimOccluder* s : slims) {
      if (auto h = s->intersect(ray.origin, ray.dir, ray.t_min, best)) {
        best = h->t;
        hit = h;
      }
    }
    if (!hit) return false;
    *depth = dot(ray.origin + hit->t * ray.dir - basis.eye, basis.forward);
    *normal = hit->n;
    return true;
  };
  parallel_items(cam.height, threads, [&](int y) {
    const int py = cam.height - 1 - y;  // GL rows count from the bottom
    for (int x = 0; x < cam.width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * cam.width + x;
      double depth = 0.0;
      Vec3 normal{};
      if (!trace(x + 0.5, py + 0.5, &depth, &normal)) continue;
      out.covered[i] = 1;
      if (samples > 1) {
        double sum_depth = 0.0;
        Vec3 sum_normal{0.0, 0.0, 0.0};
        int hits = 0;
        for (int sy = 0; sy < samples; ++sy) {
          for (int sx = 0; sx < samples; ++sx) {
            double d = 0.0;
            Vec3 nn{};
            if (!trace(x + (sx + 0.5) / samples, py + (sy + 0.5) / samples, &d, &nn)) continue;
            sum_depth += d;
            sum_normal = sum_normal + nn;
            ++hits;
          }
        }
        if (hits > 0) {
          depth = sum_depth / hits;
          if (length(sum_normal) > 0.0) normal = normalize(sum_normal);
        }
      }
      out.depth[i] = static_cast<float>(depth);
      out.normal[i] = normal;
    }
  });
  return out;
}

SlimPixels slim_from_surface(const std::vector<float>& surface, int width, int height) {
  SlimPixels out;
  out.width = width;
  out.height = height;
  const std::size_t n = static_cast<std::size_t>(width) * height;
  out.covered.assign(n, 0);
  out.depth.assign(n, 0.0f);
  out.normal.assign(n, Vec3{0.0, 0.0, 0.0});
  if (surface.size() < 4 * n) return out;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 v{surface[4 * i], surface[4 * i + 1], surface[4 * i + 2]};
    const double len = length(v);
    if (!(len > 0.0)) continue;
    out.covered[i] = 1;
    out.depth[i] = surface[4 * i + 3];
    out.normal[i] = (1.0 / len) * v;
  }
  return out;
}

SlimErrors compare_slim(const SlimPixels& gpu, const SlimPixels& ref, double size) {
  SlimErrors e;
  const int w = ref.width, h = ref.height;
  const double to10 = 10.0 / size;
  std::vector<double> angles, depths, interior_angles, interior_depths;
  double depth_sum = 0.0, crease_sum = 0.0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const bool r = ref.covered[i] != 0, g = gpu.covered[i] != 0;
      if (r) ++e.reference_pixels;
      // How many of the 3x3 neighbourhood the reference covers (off-image: not).
      auto neighbours = [&] {
        int n = 0;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (xx >= 0 && yy >= 0 && xx < w && yy < h && ref.covered[static_cast<std::size_t>(yy) * w + xx]) {
              ++n;
            }
          }
        }
        return n;
      };
      if (r && !g) {
        ++e.holes;
        if (neighbours() == 9) ++e.interior_holes;
      }
      if (g && !r) {
        ++e.spurious;
        if (neighbours() == 0) ++e.spurious_far;
      }
      if (!(r && g)) continue;
      const double dz = std::abs(static_cast<double>(gpu.depth[i]) - ref.depth[i]);
      // A different layer of the surface (the points' nearest layer is not
      // the reference's): counted apart, not as a depth error.
      if (dz > 0.1 * size) {
        ++e.occluded;
        continue;
      }
      ++e.compared;
      depth_sum += dz * to10;
      e.depth_max = std::max(e.depth_max, dz * to10);
      depths.push_back(dz * to10);
      const double c = std::clamp(dot(gpu.normal[i], ref.normal[i]), -1.0, 1.0);
      const double angle = std::acos(c) * 180.0 / std::numbers::pi;
      angles.push_back(angle);
      bool interior = true, crease = false;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= w || yy >= h) {
            interior = false;
            continue;
          }
          const std::size_t j = static_cast<std::size_t>(yy) * w + xx;
          if (!ref.covered[j] || !gpu.covered[j]) {
            interior = false;
            continue;
          }
          if (dot(ref.normal[j], ref.normal[i]) < std::cos(30.0 * std::numbers::pi / 180.0)) crease = true;
        }
      }
      if (interior) {
        ++e.interior;
        interior_angles.push_back(angle);
        interior_depths.push_back(dz * to10);
        if (crease) {
          ++e.crease_pixels;
          crease_sum += angle;
        }
      }
    }
  }
  auto p99 = [](std::vector<double>& v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v[static_cast<std::size_t>(0.99 * static_cast<double>(v.size() - 1))];
  };
  e.interior_normal_p99_deg = p99(interior_angles);
  e.interior_depth_p99 = p99(interior_depths);
  if (e.crease_pixels > 0) e.crease_normal_mean_deg = crease_sum / static_cast<double>(e.crease_pixels);
  if (e.compared > 0) {
    e.depth_mean = depth_sum / static_cast<double>(e.compared);
    double sum = 0.0;
    for (double a : angles) sum += a;
    e.normal_mean_deg = sum / static_cast<double>(angles.size());
    std::sort(angles.begin(), angles.end());
    std::sort(depths.begin(), depths.end());
    e.depth_p99 = depths[static_cast<std::size_t>(0.99 * static_cast<double>(depths.size() - 1))];
    e.normal_max_deg = angles.back();
    e.normal_p99_deg = angles[static_cast<std::size_t>(0.99 * static_cast<double>(angles.size() - 1))];
  }
  return e;
}

}  // namespace beamcast
