#include "protocol/camera.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace beamcast {

double length(const Vec3& a) { return std::hypot(a[0], a[1], a[2]); }

Vec3 normalize(const Vec3& a) {
  const double len = length(a);  // hypot: no overflow or underflow in the squares
  if (len >= 1e-300 && len <= 1e300) return (1.0 / len) * a;
  // Scale-free for the rest (1 / len would overflow for a subnormal length):
  // divide by the largest component first. Zero stays NaN, as before.
  const double m = std::max({std::abs(a[0]), std::abs(a[1]), std::abs(a[2])});
  if (!(m > 0.0) || !std::isfinite(m)) return (1.0 / len) * a;
  const Vec3 s{a[0] / m, a[1] / m, a[2] / m};
  return (1.0 / length(s)) * s;
}

Vec3 rotate(const std::array<double, 4>& q, const Vec3& v) {
  // v' = v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z)
  const Vec3 u{q[1], q[2], q[3]};
  const Vec3 uv = cross(u, v);
  const Vec3 uuv = cross(u, uv);
  return v + (2.0 * q[0]) * uv + 2.0 * uuv;
}

CameraBasis camera_basis(const Camera& cam) {
  CameraBasis b;
  b.eye = cam.position;
  if (cam.rotation) {
    const auto& r = *cam.rotation;
    const double n = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
    const std::array<double, 4> q{r[0] / n, r[1] / n, r[2] / n, r[3] / n};
    b.right = normalize(rotate(q, {1.0, 0.0, 0.0}));
    b.up = normalize(rotate(q, {0.0, 1.0, 0.0}));
    b.forward = normalize(rotate(q, {0.0, 0.0, -1.0}));
  } else {
    const Vec3 target = cam.target.value_or(cam.position + Vec3{0.0, 0.0, -1.0});
    b.forward = normalize(target - cam.position);
    b.right = normalize(cross(b.forward, cam.up));
    b.up = cross(b.right, b.forward);
  }
  b.aspect = static_cast<double>(cam.width) / static_cast<double>(cam.height);
  b.tan_half_fov = std::tan(0.5 * cam.fov_y_deg * std::numbers::pi / 180.0);
  b.half_height = 0.5 * cam.ortho_height;
  return b;
}

Ray camera_ray_ndc(const Camera& cam, const CameraBasis& b, double nx, double ny) {
  Ray ray;
  if (cam.projection == Projection::kPerspective) {
    const Vec3 d = b.forward + (nx * b.tan_half_fov * b.aspect) * b.right +
                   (ny * b.tan_half_fov) * b.up;
    ray.origin = b.eye;
    ray.dir = normalize(d);
    // Near and far are planes of constant view depth; convert to ray distance.
    const double cos_axis = dot(ray.dir, b.forward);
    ray.t_min = cam.near_plane / cos_axis;
    ray.t_max = cam.far_plane / cos_axis;
  } else {
    ray.origin = b.eye + (nx * b.half_height * b.aspect) * b.right + (ny * b.half_height) * b.up;
    ray.dir = b.forward;
    ray.t_min = cam.near_plane;
    ray.t_max = cam.far_plane;
  }
  return ray;
}

Ray camera_ray(const Camera& cam, const CameraBasis& b, int px, int py) {
  const double nx = 2.0 * (px + 0.5) / cam.width - 1.0;
  const double ny = 2.0 * (py + 0.5) / cam.height - 1.0;
  return camera_ray_ndc(cam, b, nx, ny);
}

std::optional<std::array<double, 2>> window_position(const Camera& cam, const CameraBasis& b,
                                                     const Vec3& p) {
  const Vec3 v = p - b.eye;
  double half_h = b.half_height;
  if (cam.projection == Projection::kPerspective) {
    const double z = dot(v, b.forward);
    if (!(z > cam.near_plane)) return std::nullopt;
    half_h = z * b.tan_half_fov;
  }
  const double nx = dot(v, b.right) / (half_h * b.aspect);
  const double ny = dot(v, b.up) / half_h;
  return std::array<double, 2>{(nx + 1.0) * 0.5 * cam.width, (ny + 1.0) * 0.5 * cam.height};
}

}  // namespace beamcast
