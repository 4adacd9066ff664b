// CPU reference renderer, double precision. It shares the scene model and the
// camera math (protocol/) with the GPU path and nothing else: it integrates f
// along each ray directly with adaptive quadrature, never through a table, and
// intersects occluders analytically.
#pragma once

#include "protocol/scene.hpp"
#include "render/image.hpp"

namespace beamcast {

struct ReferenceOptions {
  int threads = 0;          // 0: std::thread::hardware_concurrency()
  double rel_tol = 1e-10;   // quadrature tolerance per ray segment
};

// Linear HDR image of `cam` (rows top-down): background or Lambert-shaded
// occluder, plus the beams' energy along the visible part of each ray.
HdrImage render_reference(const Scene& scene, const Camera& cam, const ReferenceOptions& opts = {});

// The energy one beam adds along a ray for t in [t0, t1] (world units), i.e.
// (1 / r) * integral f(dist(p(t), beam) / r) dt, without color or intensity.
// Exposed for tests.
double beam_energy_reference(const Beam& beam, const Vec3& origin, const Vec3& dir, double t0,
                             double t1, double rel_tol = 1e-10);

}  // namespace beamcast
