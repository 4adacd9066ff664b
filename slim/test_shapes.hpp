// Small SLIM surfaces generated in code for the tests and benches (issue 16):
// a sphere, a torus and a plane covered by support spheres whose local
// quadratics are the shapes' own second-order expansions, so the blended
// surface lies within a known distance of the exact shape.
// Header-only; here in slim/ (not tests/) so bench/ can use it too.
#pragma once

#include <cmath>
#include <numbers>
#include <vector>

#include "protocol/slim_model.hpp"

namespace beamcast::test {

// The orthonormal tangent frame (u, v, n) at unit normal n.
inline SlimSphere support_at(const Vec3& p, const Vec3& n, double radius) {
  const Vec3 a = std::abs(n[0]) < 0.9 ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
  const Vec3 u = normalize(cross(a, n));
  const Vec3 v = cross(n, u);
  SlimSphere s;
  s.center = p;
  s.radius = radius;
  s.rotation = quat_from_axes(u, v, n);
  return s;
}

// A sphere of radius R about c: `count` supports on a Fibonacci lattice,
// each of radius support x the lattice spacing R sqrt(4 pi / count), with
// w = -(u^2 + v^2) / (2R) (the circle's osculating paraboloid). At a
// support's rim (distance rho from its centre) the paraboloid is off the
// sphere by about rho^4 / (8 R^3).
inline std::vector<SlimSphere> slim_sphere(const Vec3& c, double R, int count, double support = 2.0) {
  std::vector<SlimSphere> out;
  const double rho = support * R * std::sqrt(4.0 * std::numbers::pi / count);
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double y = 1.0 - 2.0 * (i + 0.5) / count;
    const double r = std::sqrt(1.0 - y * y);
    const Vec3 n{r * std::cos(golden * i), y, r * std::sin(golden * i)};
    SlimSphere s = support_at(c + R * n, n, rho);
    s.poly.c = {-0.5 / R, 0.0, -0.5 / R, 0.0, 0.0, 0.0};
    out.push_back(s);
  }
  return out;
}

// A torus about c with axis y, tube centre radius Rt and tube radius rt,
// supports on an nu x nv grid, each with the torus's principal curvatures
// (k_tube = 1/rt along the tube's circle, k_ring = cos(phi) / (Rt + rt cos(phi))
// along the ring).
inline std::vector<SlimSphere> slim_torus(const Vec3& c, double Rt, double rt, int nu, int nv,
                                          double support = 1.5) {
  std::vector<SlimSphere> out;
  for (int i = 0; i < nu; ++i) {
    const double theta = 2.0 * std::numbers::pi * (i + 0.5) / nu;  // around the ring
    for (int j = 0; j < nv; ++j) {
      const double phi = 2.0 * std::numbers::pi * (j + 0.5) / nv;  // around the tube
      const Vec3 radial{std::cos(theta), 0.0, std::sin(theta)};
      const Vec3 n = std::cos(phi) * radial + Vec3{0.0, std::sin(phi), 0.0};
      const Vec3 p = c + (Rt + rt * std::cos(phi)) * radial + Vec3{0.0, rt * std::sin(phi), 0.0};
      const Vec3 ring{-std::sin(theta), 0.0, std::cos(theta)};  // along the ring
      const Vec3 tube = cross(n, ring);                           // along the tube's circle
      const double spacing = std::max(2.0 * std::numbers::pi * (Rt + rt) / nu,
                                      2.0 * std::numbers::pi * rt / nv);
      SlimSphere s;
      s.center = p;
      s.radius = support * spacing;
      s.rotation = quat_from_axes(ring, tube, n);
      const double k_ring = std::cos(phi) / (Rt + rt * std::cos(phi));
      s.poly.c = {-0.5 * k_ring, 0.0, -0.5 / rt, 0.0, 0.0, 0.0};
      out.push_back(s);
    }
  }
  return out;
}

// The plane y = h over [-half, half]^2 in x and z, facing +y: a grid of
// flat supports (w = 0).
inline std::vector<SlimSphere> slim_plane(double h, double half, int n) {
  std::vector<SlimSphere> out;
  const double step = 2.0 * half / n;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const Vec3 p{-half + (i + 0.5) * step, h, -half + (j + 0.5) * step};
      out.push_back(support_at(p, {0.0, 1.0, 0.0}, 1.5 * step));
    }
  }
  return out;
}

// A roof y = -slope |x| over [-half, half]^2 (a ridge along z at x = 0):
// n x n supports on the roof, each in the world frame (u = x, v = z, w = y)
// with the crease rule min(P1, P2) of the two planes relative to its centre,
// so every support holds the roof exactly and F = y - roof(x) wherever a
// support reaches.
inline std::vector<SlimSphere> slim_roof(double slope, double half, int n) {
  std::vector<SlimSphere> out;
  const double step = 2.0 * half / n;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double cx = -half + (i + 0.5) * step, cz = -half + (j + 0.5) * step;
      SlimSphere sp;
      sp.center = {cx, -slope * std::abs(cx), cz};
      sp.radius = 1.5 * step;
      sp.rotation = quat_from_axes({1.0, 0.0, 0.0}, {0.0, 0.0, -1.0}, {0.0, 1.0, 0.0});
      // local w = roof(cx + u) - roof(cx) = min(-slope (cx + u), slope (cx + u)) + slope |cx|
      sp.poly.c = {0.0, 0.0, 0.0, -slope, 0.0, slope * (std::abs(cx) - cx)};
      sp.poly2.c = {0.0, 0.0, 0.0, slope, 0.0, slope * (std::abs(cx) + cx)};
      sp.crease = SlimCrease::kMin;
      out.push_back(sp);
    }
  }
  return out;
}

}  // namespace beamcast::test
