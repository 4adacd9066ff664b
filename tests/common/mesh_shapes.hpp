// Triangle meshes generated in code for the SLIM fitter's tests (issue 16):
// a UV sphere, a torus and a cube with sharp edges, outward-facing
// (counter-clockwise seen from outside), a few thousand triangles each.
#pragma once

#include <cmath>
#include <numbers>

#include "slim/mesh_io.hpp"

namespace beamcast::test {

// The sphere of radius R about c: `rings` latitude bands of `segments` quads,
// fans of triangles at the poles.
inline slim::TriangleMesh uv_sphere(const Vec3& c, double R, int rings, int segments) {
  slim::TriangleMesh m;
  m.vertices.push_back(c + Vec3{0.0, R, 0.0});  // north pole
  for (int i = 1; i < rings; ++i) {
    const double th = std::numbers::pi * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double ph = 2.0 * std::numbers::pi * j / segments;
      m.vertices.push_back(
          c + R * Vec3{std::sin(th) * std::cos(ph), std::cos(th), -std::sin(th) * std::sin(ph)});
    }
  }
  m.vertices.push_back(c + Vec3{0.0, -R, 0.0});  // south pole
  const auto south = static_cast<std::uint32_t>(m.vertices.size() - 1);
  auto at = [&](int ring, int seg) {  // ring 1 .. rings-1
    return static_cast<std::uint32_t>(1 + (ring - 1) * segments + (seg % segments));
  };
  for (int j = 0; j < segments; ++j) {
    m.triangles.push_back({0, at(1, j), at(1, j + 1)});
    m.triangles.push_back({south, at(rings - 1, j + 1), at(rings - 1, j)});
  }
  for (int i = 1; i + 1 < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  return m;
}

// The torus about c with axis y, ring radius Rt and tube radius rt.
inline slim::TriangleMesh torus(const Vec3& c, double Rt, double rt, int nu, int nv) {
  slim::TriangleMesh m;
  for (int i = 0; i < nu; ++i) {
    const double th = 2.0 * std::numbers::pi * i / nu;
    for (int j = 0; j < nv; ++j) {
      const double ph = 2.0 * std::numbers::pi * j / nv;
      const double rr = Rt + rt * std::cos(ph);
      m.vertices.push_back(c + Vec3{rr * std::cos(th), rt * std::sin(ph), rr * std::sin(th)});
    }
  }
  auto at = [&](int i, int j) { return static_cast<std::uint32_t>((i % nu) * nv + (j % nv)); };
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      m.triangles.push_back({at(i, j), at(i, j + 1), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i + 1, j)});
    }
  }
  return m;
}

// The cube [c - h, c + h]^3, each face an n x n grid of quad pairs (face
// vertices not shared between faces: the edges stay sharp).
inline slim::TriangleMesh cube(const Vec3& c, double h, int n) {
  slim::TriangleMesh m;
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign = -1; sign <= 1; sign += 2) {
      Vec3 nrm{0.0, 0.0, 0.0};
      nrm[static_cast<std::size_t>(axis)] = sign;
      Vec3 a{0.0, 0.0, 0.0}, b{0.0, 0.0, 0.0};
      a[static_cast<std::size_t>((axis + 1) % 3)] = 1.0;
      b[static_cast<std::size_t>((axis + 2) % 3)] = 1.0;
      if (sign < 0) std::swap(a, b);  // keeps a x b = outward normal
      const auto base = static_cast<std::uint32_t>(m.vertices.size());
      for (int i = 0; i <= n; ++i) {
        for (int j = 0; j <= n; ++j) {
          const double s = -h + 2.0 * h * i / n, t = -h + 2.0 * h * j / n;
          m.vertices.push_back(c + h * nrm + s * a + t * b);
        }
      }
      auto at = [&](int i, int j) { return base + static_cast<std::uint32_t>(i * (n + 1) + j); };
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
          m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        }
      }
    }
  }
  return m;
}

}  // namespace beamcast::test
