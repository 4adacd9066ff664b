// CPU reference renderer, double precision. It shares the scene model and the
// camera math (protocol/) with the GPU path and nothing else: it integrates f
// along each ray directly with adaptive quadrature, never through a table, and
// intersects occluders analytically.
#pragma once

#include <cstdint>
#include <functional>

#include "protocol/scene.hpp"
#include "render/image.hpp"

namespace beamcast {

struct ReferenceOptions {
  int threads = 0;          // 0: std::thread::hardware_concurrency()
  double rel_tol = 1e-10;   // quadrature tolerance per ray segment
  // Scenes with lights (Scene::has_gi): path-traced samples per pixel and seed
  // of the surfaces' radiance (gi/path_tracer.hpp).
  int gi_spp = 64;
  std::uint64_t gi_seed = 1;
  // Surface interactions a path may have (PathTraceOptions::max_depth): 1
  // is direct light only (emitters seen and next-event estimation at the
  // first surface), which with the full image splits an error into its
  // direct and indirect parts.
  int gi_max_depth = 32;
  // Scalar volumes (Scene::volumes): the march's step in world units (0: a
  // sixteenth of the volume's smallest voxel spacing, each step sampled at
  // its middle), and whether to sample the exact field of procedural
  // volumes (Volume::exact) instead of the trilinear grid.
  double volume_step = 0.0;
  bool volume_exact = false;
  // Progress: (rows done, rows in all), from the worker threads, after each
  // row; a lit scene's path-traced rows come first, then the shading's.
  std::function<void(int done, int total)> on_progress;
};

// One volume's front-to-back composite along a ray (unit `dir`) over
// t in [t0, t1]: its colour and what it lets through. Steps of `step`
// (world units; the last one shorter), each sampled at its middle, opacity
// corrected for the step's length: alpha = 1 - (1 - opacity)^(ds / unit).
struct VolumeComposite {
  Color color{0.0, 0.0, 0.0};
  double transmittance = 1.0;
};
VolumeComposite volume_composite_reference(const Volume& volume, const Vec3& origin, const Vec3& dir,
                                           double t0, double t1, double step, bool exact = false);
// The ray distances [t0, t1] where the ray meets the volume's box, clipped to
// [t_min, t_max]; false if it misses.
bool volume_interval(const Volume& volume, const Vec3& origin, const Vec3& dir, double t_min,
                     double t_max, double* t0, double* t1);

// Linear HDR image of `cam` (rows top-down): background or Lambert-shaded
// occluder, plus the beams' energy along the visible part of each ray. With
// lights (Scene::has_gi) the path tracer gives each pixel's radiance instead
// (surfaces lit by the lights, background where its paths leave the scene);
// the beams are added on top, clipped at the surface the pixel's centre sees.
// A medium (Scene::has_medium) attenuates the surface by e^(-sigma_t t) (the
// background, at infinity, entirely) and each beam within itself; in lit
// scenes the path tracer follows paths through it (free flights, single and
// multiple scattering, transmittance to the lights). Scalar volumes are
// composited over what lies behind them (farther volumes first), and the
// beams' light is attenuated by the volumes in front of each point of it.
HdrImage render_reference(const Scene& scene, const Camera& cam, const ReferenceOptions& opts = {});

// The energy one beam adds along a ray for t in [t0, t1] (world units), i.e.
// (1 / r) * integral f(dist(p(t), beam) / r) e^(-sigma_t t) dt (t from the
// ray's origin; sigma_t a medium's extinction, 0: none), without color or
// intensity. Exposed for tests.
double beam_energy_reference(const Beam& beam, const Vec3& origin, const Vec3& dir, double t0,
                             double t1, double rel_tol = 1e-10, double sigma_t = 0.0);

}  // namespace beamcast
