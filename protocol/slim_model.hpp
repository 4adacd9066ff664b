// SLIM implicit surfaces (seed 003, digest §3): the model shared by the scene
// parser, the CPU reference, the fitter (slim/) and the GPU packing. Pure
// double-precision math; no GL, no files (slim_io.hpp reads and writes them).
//
// A surface is a set of support spheres. Sphere i has a centre p_i, radius
// r_i, a rotation R_i (unit quaternion) from its local frame (u, v, w) to
// world, and a local height field w = f_i(u, v): one bivariate quadratic
//   q(u, v) = A u^2 + B u v + C v^2 + D u + E v + F
// or, on a crease, the min or max of two. A world point x has local
// coordinates (u, v, w) = R_i^T (x - p_i). The blended implicit function is
//   F(x) = sum_i w_i(x) (w_i - f_i(u_i, v_i)) / sum_i w_i(x)
// with the compactly supported weight w_i(x) = slim_weight(|x - p_i| / r_i);
// the surface is F = 0 where sum w_i > 0. The local normal of sphere i is
// (-df/du, -df/dv, 1), rotated to world: F grows along it (outside).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "protocol/vec.hpp"

namespace beamcast {

// A w = A u^2 + B u v + C v^2 + D u + E v + F.
struct SlimPoly {
  std::array<double, 6> c{};  // A, B, C, D, E, F

  double eval(double u, double v) const {
    return c[0] * u * u + c[1] * u * v + c[2] * v * v + c[3] * u + c[4] * v + c[5];
  }
  // (df/du, df/dv)
  std::array<double, 2> grad(double u, double v) const {
    return {2.0 * c[0] * u + c[1] * v + c[3], c[1] * u + 2.0 * c[2] * v + c[4]};
  }
};

// How a sphere's second polynomial combines with its first (creases).
enum class SlimCrease : std::uint8_t { kNone = 0, kMin = 1, kMax = 2 };
std::string_view crease_name(SlimCrease c);

struct SlimSphere {
  Vec3 center{};
  double radius = 1.0;
  std::array<double, 4> rotation{1.0, 0.0, 0.0, 0.0};  // unit quaternion (w, x, y, z)
  SlimPoly poly;
  SlimPoly poly2;  // used only with a crease
  SlimCrease crease = SlimCrease::kNone;

  // f(u, v), the crease rule applied.
  double height(double u, double v) const;
  // (df/du, df/dv) of the polynomial that height() took.
  std::array<double, 2> height_grad(double u, double v) const;
  // World -> local (u, v, w) and back.
  Vec3 to_local(const Vec3& x) const;
  Vec3 to_world(const Vec3& local) const;
  // The surface point above (u, v) in world space, and its unit world
  // normal from the local gradient (-df/du, -df/dv, 1).
  Vec3 surface_point(double u, double v) const;
  Vec3 surface_normal(double u, double v) const;
};

// The blending weight as a function of q = |x - p| / r: (1 - q^2)^3 for
// q < 1, else 0. Gaussian-like (close to exp(-3 q^2) near the centre),
// compactly supported, C^2 at q = 1 (value, slope and curvature vanish).
inline double slim_weight(double q) {
  if (!(q < 1.0)) return 0.0;
  const double s = 1.0 - q * q;
  return s * s * s;
}

// A bound on the slope |grad f| of either polynomial over |u|, |v| <= r.
double slim_max_slope(const SlimSphere& s);

// [lo, hi] holding the local height w of every point of the sphere's patch
// that lies inside the sphere (from a 32 x 32 grid of the height field,
// padded by the slope bound times the grid step), within [-r, r]. The GPU
// bounds each patch by the sphere within this slab (slim.evaluation
// "patch").
std::array<double, 2> slim_height_range(const SlimSphere& s);

// The spheres' bounds (each sphere's box), empty for no spheres.
Aabb slim_bounds(const std::vector<SlimSphere>& spheres);

// Applies world = translate + scale * rotate(rotation, x) to every sphere:
// centres move, radii and the local heights scale (the height field's
// coefficients: A, B, C by 1/scale, D, E unchanged, F by scale), rotations
// compose. `scale` > 0.
void transform_slim(std::vector<SlimSphere>& spheres, const Vec3& translate, double scale,
                    const std::array<double, 4>& rotation);

// Quaternion product a * b (w, x, y, z): rotate(a * b, v) = rotate(a, rotate(b, v)).
std::array<double, 4> quat_mul(const std::array<double, 4>& a, const std::array<double, 4>& b);
// The unit quaternion whose rotation takes the local axes (u, v, w) to the
// orthonormal right-handed world axes (x_axis, y_axis, z_axis).
std::array<double, 4> quat_from_axes(const Vec3& x_axis, const Vec3& y_axis, const Vec3& z_axis);

// A bounding volume hierarchy over the support spheres, for the CPU
// reference: which spheres a ray segment crosses, and F with its gradient at
// a point from the spheres near it.
class SlimField {
 public:
  explicit SlimField(const std::vector<SlimSphere>* spheres);

  // F(x) and sum w(x); F is 0 with sum 0 where no support reaches x.
  struct Value {
    double f = 0.0;
    double weight = 0.0;
  };
  Value value(const Vec3& x) const;
  // Unit gradient of F at x (central differences in double, step
  // 1e-6 of the smallest radius reaching x); the outward normal.
  Vec3 normal(const Vec3& x) const;

  // The first zero of F along o + t v in [t_min, t_max] (v unit), inside
  // the supports: each maximal interval the supports cover is scanned in
  // steps of at most `step_frac` times the smallest radius active there,
  // sign changes bracketed and refined by bisection to 1e-12 of the radius.
  struct Hit {
    double t = 0.0;
    Vec3 n{};  // outward unit normal
  };
  std::optional<Hit> intersect(const Vec3& o, const Vec3& v, double t_min, double t_max,
                               double step_frac = 0.05) const;

  // The spheres whose support contains x (indices).
  void spheres_at(const Vec3& x, std::vector<std::uint32_t>& out) const;

 private:
  struct Node {
    Aabb box;
    std::uint32_t first = 0, count = 0;  // leaf: spheres [first, first + count) of order_
    std::uint32_t left = 0, right = 0;   // inner: children (count == 0)
  };
  std::uint32_t build(std::uint32_t first, std::uint32_t count);
  template <class Visit>
  void visit_segment(const Vec3& o, const Vec3& v, double t0, double t1, Visit&& f) const;
  Value value_of(const Vec3& x, const std::vector<std::uint32_t>& candidates) const;

  const std::vector<SlimSphere>* spheres_;
  std::vector<std::uint32_t> order_;
  std::vector<Node> nodes_;
};

}  // namespace beamcast
