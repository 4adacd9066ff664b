// Typed reads of scene values that need the scene's limits (positions,
// sizes) or its conventions (directions, albedo, quaternions).
#include "protocol/scene_readers.hpp"

#include <algorithm>
#include <cmath>

#include "protocol/camera.hpp"

namespace beamcast::json_read {

Vec3 read_point(const Node& n, const SceneLimits& limits) {
  return check_coordinates(n, read_vec3(n), limits.max_abs_coordinate);
}

double read_size(const Node& n, const SceneLimits& limits) {
  const double v = check_positive(n, read_number(n));
  if (v > limits.max_abs_coordinate || v < kMinLength) {
    fail("out_of_range", n.path,
         n.name() + " must be in [" + format_number(kMinLength) + ", " +
             format_number(limits.max_abs_coordinate) +
             "] (limit max_abs_coordinate; below 1e-15 the GPU's floats lose it), got " +
             format_number(v));
  }
  return v;
}

bool normalizable(const Vec3& v) {
  const double len = length(v);
  if (!(len > 0.0) || !std::isfinite(len)) return false;
  const Vec3 u = normalize(v);
  return std::isfinite(u[0]) && std::isfinite(u[1]) && std::isfinite(u[2]);
}

Vec3 read_direction(const Node& n) {
  const Vec3 v = read_vec3(n);
  if (!normalizable(v)) {
    fail("invalid_value", n.path,
         n.name() + " must be a nonzero direction vector, got [" +
             format_number(v[0]) + ", " + format_number(v[1]) + ", " + format_number(v[2]) + "]");
  }
  return v;
}

double read_radiometric(const Node& n) { return check_closed(n, read_number(n), 0.0, kMaxRadiometric); }

Color read_color(const Node& n) {
  Color c = read_vec3(n);
  for (std::size_t i = 0; i < 3; ++i)
    check_closed(Node{&n.json()[i], child_path(n.path, i)}, c[i], 0.0, kMaxRadiometric);
  return c;
}

Color read_albedo(const Node& n) {
  Color c = read_vec3(n);
  for (std::size_t i = 0; i < 3; ++i)
    check_closed(Node{&n.json()[i], child_path(n.path, i)}, c[i], 0.0, 1.0);
  return c;
}

std::array<double, 4> read_quaternion(const Node& n) {
  auto q = read_numbers<4>(n);
  // Scale-free: divided by its largest component first, the sum of squares
  // neither underflows (a 1e-200-long quaternion) nor overflows.
  double m = 0.0;
  for (const double c : q) m = std::max(m, std::abs(c));
  if (!(m > 0.0)) {
    fail("invalid_value", n.path,
         n.name() + " must be a quaternion [w, x, y, z] with nonzero norm, got all zeros");
  }
  for (double& c : q) c /= m;
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (double& c : q) c /= norm;
  return q;
}

MeshTransform parse_mesh_transform(const ObjectReader& o, const SceneLimits& limits) {
  MeshTransform xf;
  if (auto t = o.optional("translate")) xf.translate = read_point(*t, limits);
  if (auto s = o.optional("scale")) {
    if (s->json().is_number()) {
      const double v = read_number(*s);
      xf.scale = {v, v, v};
    } else {
      xf.scale = read_vec3(*s);
    }
    // Negative factors mirror the mesh (allowed); zero flattens it (refused).
    for (double v : xf.scale) {
      if (!(std::abs(v) > 0.0) || std::abs(v) > limits.max_abs_coordinate) {
        fail("out_of_range", s->path,
             "scale factors must be nonzero with magnitude <= max_abs_coordinate, got " +
                 format_number(v));
      }
    }
  }
  if (auto r = o.optional("rotation")) xf.rotation = read_quaternion(*r);
  return xf;
}

}  // namespace beamcast::json_read
