// One support sphere's fit (slim/fit.cpp): a weighted least-squares quadratic
// height field in the frame of the points' mean normal, or on a crease two of
// them, combined by min or max. Weights: each point's share of the surface
// times slim_weight(|x - c| / r), the same falloff F blends with.
#pragma once

#include <cstdint>
#include <vector>

#include "protocol/slim_model.hpp"

namespace beamcast::slim {

struct FitPoint {
  Vec3 p;       // position
  Vec3 n;       // unit normal
  double area;  // share of the surface
};

struct LocalFitSettings {
  double max_normal_deg = 60.0;  // spread of normals about their mean that a height field takes
  double crease_deg = 30.0;      // least angle between the two groups of a crease
};

struct LocalFit {
  bool ok = false;
  SlimSphere sphere;
  // The largest distance (|w - f(u, v)| / sqrt(1 + |grad f|^2), mesh units)
  // from a point inside the sphere to the fitted surface.
  double error = 0.0;
};

// One quadratic in the mean normal's frame; not ok when the normals spread
// wider than max_normal_deg (unless `force`) or the system is singular.
LocalFit fit_single(const std::vector<FitPoint>& pts, const std::vector<std::uint32_t>& ball,
                    const Vec3& c, double r, const LocalFitSettings& s, bool force);

// Normals split in two groups (2-means, weighted) more than crease_deg apart,
// each within max_normal_deg and within that angle of its own mean: one quadratic per group in
// the frame of the groups' bisector; min or max, whichever reproduces the points.
LocalFit fit_crease(const std::vector<FitPoint>& pts, const std::vector<std::uint32_t>& ball,
                    const Vec3& c, double r, const LocalFitSettings& s);

// Solves the 6x6 weighted normal equations of w = A u^2 + B uv + C v^2 + D u
// + E v + F over samples (u, v, w, weight) by Cholesky in double, with a
// 1e-9 relative ridge on A..E against rank-deficient sets (points on a line).
// False with fewer than 6 samples of positive weight (as many as unknowns)
// or a matrix that is not positive definite.
bool solve_quadratic(const std::vector<std::array<double, 4>>& samples, SlimPoly* out);

}  // namespace beamcast::slim
