// Camera frame and view rays (protocol/camera.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "protocol/camera.hpp"

namespace beamcast {
namespace {

constexpr double kEps = 1e-12;

void expect_vec_near(const Vec3& a, const Vec3& b, double eps = kEps) {
  EXPECT_NEAR(a[0], b[0], eps);
  EXPECT_NEAR(a[1], b[1], eps);
  EXPECT_NEAR(a[2], b[2], eps);
}

void expect_orthonormal(const CameraBasis& b) {
  EXPECT_NEAR(length(b.right), 1.0, kEps);
  EXPECT_NEAR(length(b.up), 1.0, kEps);
  EXPECT_NEAR(length(b.forward), 1.0, kEps);
  EXPECT_NEAR(dot(b.right, b.up), 0.0, kEps);
  EXPECT_NEAR(dot(b.right, b.forward), 0.0, kEps);
  EXPECT_NEAR(dot(b.up, b.forward), 0.0, kEps);
  // Right-handed: right x up = -forward (camera looks down its local -Z).
  expect_vec_near(cross(b.right, b.up), -1.0 * b.forward);
}

Camera look_at(Vec3 pos, Vec3 target, Vec3 up = {0, 1, 0}) {
  Camera c;
  c.position = pos;
  c.target = target;
  c.up = up;
  return c;
}

// Many look-at and quaternion poses, not one hand-picked case.
TEST(Camera, BasisOrthonormalLookAt) {
  for (int i = 0; i < 50; ++i) {
    const double a = 0.37 * i;
    const Camera c = look_at({3 * std::cos(a), 0.5 * i - 10, 2 * std::sin(1.3 * a)},
                             {std::sin(a), 1, -2}, {0.1 * std::sin(a), 1, 0.2});
    const CameraBasis b = camera_basis(c);
    expect_orthonormal(b);
    expect_vec_near(b.forward, normalize(*c.target - c.position));
    EXPECT_GT(dot(b.up, c.up), 0.0);  // up keeps the requested side
  }
}

TEST(Camera, BasisOrthonormalQuaternion) {
  for (int i = 0; i < 50; ++i) {
    Camera c;
    // Deliberately not unit length: camera_basis normalizes.
    c.rotation = std::array<double, 4>{std::cos(0.3 * i) * 2, std::sin(0.7 * i),
                                       0.5 * std::cos(1.1 * i), 0.3};
    expect_orthonormal(camera_basis(c));
  }
}

TEST(Camera, IdentityQuaternionLooksDownMinusZ) {
  Camera c;
  c.rotation = std::array<double, 4>{1, 0, 0, 0};
  const CameraBasis b = camera_basis(c);
  expect_vec_near(b.forward, {0, 0, -1});
  expect_vec_near(b.up, {0, 1, 0});
  expect_vec_near(b.right, {1, 0, 0});
}

TEST(Camera, QuaternionRotatesCameraAxesIntoWorld) {
  // 90 degrees about +Y turns local -Z into world -X.
  Camera c;
  c.rotation = std::array<double, 4>{std::sqrt(0.5), 0, std::sqrt(0.5), 0};
  expect_vec_near(camera_basis(c).forward, {-1, 0, 0});
}

TEST(Camera, NoOrientationLooksDownMinusZ) {
  const CameraBasis b = camera_basis(Camera{});
  expect_vec_near(b.forward, {0, 0, -1});
  expect_vec_near(b.up, {0, 1, 0});
}

TEST(Camera, CenterPixelRayIsForward) {
  Camera c = look_at({1, 2, 3}, {-4, 0, 1});
  c.width = 65;  // odd sizes have a pixel whose centre is the image centre
  c.height = 33;
  const CameraBasis b = camera_basis(c);
  const Ray r = camera_ray(c, b, 32, 16);
  expect_vec_near(r.dir, b.forward);
  expect_vec_near(r.origin, c.position);
  EXPECT_NEAR(r.t_min, c.near_plane, kEps);
  EXPECT_NEAR(r.t_max, c.far_plane, 1e-9);
}

TEST(Camera, PerspectiveNearFarAreViewDepthPlanes) {
  Camera c = look_at({0, 0, 0}, {0, 0, -1});
  c.near_plane = 0.5;
  c.far_plane = 50;
  c.width = 200;
  c.height = 100;
  c.fov_y_deg = 90;
  const CameraBasis b = camera_basis(c);
  for (int px : {0, 37, 199}) {
    for (int py : {0, 50, 99}) {
      const Ray r = camera_ray(c, b, px, py);
      const double cos_axis = dot(r.dir, b.forward);
      EXPECT_NEAR(r.t_min, c.near_plane / cos_axis, 1e-12);
      EXPECT_NEAR(r.t_max, c.far_plane / cos_axis, 1e-9);
      // The points at t_min / t_max lie on the near / far planes.
      EXPECT_NEAR(dot(r.t_min * r.dir, b.forward), c.near_plane, 1e-12);
      EXPECT_NEAR(dot(r.t_max * r.dir, b.forward), c.far_plane, 1e-9);
    }
  }
}

TEST(Camera, PerspectiveCornerMatchesFov) {
  Camera c = look_at({0, 0, 0}, {0, 0, -1});
  c.fov_y_deg = 60;
  c.width = 300;
  c.height = 100;
  const CameraBasis b = camera_basis(c);
  const Ray r = camera_ray_ndc(c, b, 1.0, 1.0);
  const double t = std::tan(30.0 * std::numbers::pi / 180.0);
  expect_vec_near(r.dir, normalize(Vec3{3 * t, t, -1}));
}

TEST(Camera, OrthographicRaysParallel) {
  Camera c = look_at({0, 0, 10}, {0, 0, 0});
  c.projection = Projection::kOrthographic;
  c.ortho_height = 4;
  c.width = 8;
  c.height = 4;
  const CameraBasis b = camera_basis(c);
  for (int px = 0; px < 8; ++px) {
    for (int py = 0; py < 4; ++py) {
      const Ray r = camera_ray(c, b, px, py);
      expect_vec_near(r.dir, b.forward);
      EXPECT_EQ(r.t_min, c.near_plane);
      EXPECT_EQ(r.t_max, c.far_plane);
    }
  }
  // Corner pixel centres: the view is ortho_height tall and aspect * ortho_height wide.
  const Ray r = camera_ray(c, b, 7, 3);
  expect_vec_near(r.origin, {4 - 0.5, 2 - 0.5, 10});
}

TEST(Camera, PixelRowsCountUpward) {
  Camera c = look_at({0, 0, 0}, {0, 0, -1});
  c.width = 10;
  c.height = 10;
  const CameraBasis b = camera_basis(c);
  const Ray bottom = camera_ray(c, b, 5, 0);
  const Ray top = camera_ray(c, b, 5, 9);
  EXPECT_LT(bottom.dir[1], 0.0);  // py = 0 is the bottom row
  EXPECT_GT(top.dir[1], 0.0);
  EXPECT_LT(camera_ray(c, b, 0, 5).dir[0], 0.0);  // px = 0 is the left column
}

// window_position inverts camera_ray: a point anywhere along a pixel
// centre's ray lands on that centre (1e-9 px: double rounding of a few
// dot products), for both projections and a turned, non-square camera;
// a point behind the near plane has no position.
TEST(Camera, WindowPositionInvertsCameraRay) {
  for (const Projection proj : {Projection::kPerspective, Projection::kOrthographic}) {
    Camera c = look_at({1, 2, 3}, {-2, 0.5, -4});
    c.projection = proj;
    c.width = 37;
    c.height = 23;
    c.fov_y_deg = 70;
    c.ortho_height = 3;
    const CameraBasis b = camera_basis(c);
    for (int py = 0; py < c.height; py += 5) {
      for (int px = 0; px < c.width; px += 4) {
        const Ray r = camera_ray(c, b, px, py);
        for (const double t : {r.t_min * 2.0, 1.0, 50.0}) {
          const auto w = window_position(c, b, r.origin + t * r.dir);
          ASSERT_TRUE(w.has_value());
          EXPECT_NEAR((*w)[0], px + 0.5, 1e-9);
          EXPECT_NEAR((*w)[1], py + 0.5, 1e-9);
        }
      }
    }
    if (proj == Projection::kPerspective) {
      EXPECT_FALSE(window_position(c, b, b.eye - b.forward).has_value());
      EXPECT_FALSE(window_position(c, b, b.eye + 0.5 * c.near_plane * b.forward).has_value());
    }
  }
}

TEST(Camera, RotateMatchesAxisAngle) {
  const double a = 0.8;
  const std::array<double, 4> q{std::cos(a / 2), 0, 0, std::sin(a / 2)};  // about +Z
  expect_vec_near(rotate(q, {1, 0, 0}), {std::cos(a), std::sin(a), 0});
}

}  // namespace
}  // namespace beamcast
