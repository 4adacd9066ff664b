// The path-traced reference of global illumination (issue 14, item 5): a
// double-precision CPU path tracer with next-event estimation over GiScene.
// Lambertian diffuse (f = albedo / pi), perfect mirrors, smooth glass with
// exact unpolarized Fresnel; quad lights are one-sided Lambertian emitters
// that absorb. Deterministic: each pixel has its own generator seeded from
// (seed, pixel index), so the image does not depend on the thread count.
// Derivations and measured accuracy: docs/gi.md.
#pragma once

#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include "gi/gi_scene.hpp"
#include "protocol/scene.hpp"

namespace beamcast {

struct PathTraceOptions {
  int spp = 64;            // camera paths per pixel, jittered within the pixel
  std::uint64_t seed = 1;  // with the pixel index, seeds each pixel's generator
  int threads = 0;         // 0: std::thread::hardware_concurrency()
  int max_depth = 32;  // surface interactions a path may have (Russian roulette ends most sooner)
  // path_trace: called after each row, from the worker threads (progress).
  std::function<void()> on_row;
};

// Radiance arriving at o from direction -v along o + t v (|v| = 1), t in
// (t_min, t_max], as a camera ray: emitters seen directly count, and a path
// that leaves the scene before any diffuse bounce returns the background
// (the background lights nothing). `rng` supplies the uniforms.
Color trace_radiance(const GiScene& gi, const Vec3& o, const Vec3& v, double t_min, double t_max,
                     const PathTraceOptions& opts, std::mt19937_64& rng);

// Linear radiance of every pixel of `cam`, rows from the top of the picture
// down (protocol/hdr_image.hpp's HdrImage layout): index y * width + x.
std::vector<Color> path_trace(const GiScene& gi, const Camera& cam, const PathTraceOptions& opts);

}  // namespace beamcast
