// Camera math in double precision, shared by the GPU path (which turns it into
// camera-relative float matrices) and the CPU reference (which traces rays).
#pragma once

#include <array>
#include <optional>

#include "protocol/scene.hpp"

namespace beamcast {

// Orthonormal camera frame in world space.
struct CameraBasis {
  Vec3 eye{};
  Vec3 right{};
  Vec3 up{};
  Vec3 forward{};        // viewing direction (camera looks down local -Z)
  double tan_half_fov = 0.0;  // perspective: tan(fov_y / 2)
  double half_height = 0.0;   // orthographic: half the view height
  double aspect = 1.0;        // width / height
};

// A view ray: p(t) = origin + t * dir, |dir| = 1, visible for t in [t_min, t_max]
// (t_min on the near plane, t_max on the far plane).
struct Ray {
  Vec3 origin{};
  Vec3 dir{};
  double t_min = 0.0;
  double t_max = 0.0;
};

// Requires a validated camera (see scene_json): target != position, up not
// parallel to the view direction, unit-length-able quaternion.
CameraBasis camera_basis(const Camera& cam);

// The ray through the pixel centre (px + 0.5, py + 0.5), px to the right, py
// upward from the bottom row (OpenGL window convention).
Ray camera_ray(const Camera& cam, const CameraBasis& basis, int px, int py);

// Same, for a point in normalized device coordinates [-1, 1]^2.
Ray camera_ray_ndc(const Camera& cam, const CameraBasis& basis, double ndc_x, double ndc_y);

// Where point p lands in the window, in pixels (x right, y up from the
// bottom edge; pixel (px, py) spans [px, px + 1) x [py, py + 1)): the
// inverse of camera_ray. Perspective: nothing for a point at or behind the
// near plane's depth (it has no place in the image).
std::optional<std::array<double, 2>> window_position(const Camera& cam, const CameraBasis& basis,
                                                     const Vec3& p);

}  // namespace beamcast
