// SLIM surfaces against their CPU reference (issue 16, item 4): per pixel the
// nearest zero of the blended implicit function F along the pixel's centre
// ray (in double, protocol/slim_model.hpp), and the GPU's point-sampled
// surface read back from the slim passes' sums; the errors between them.
#pragma once

#include <cstdint>
#include <vector>

#include "protocol/scene.hpp"

namespace beamcast {

// A surface per pixel, rows top-down: covered or not, view depth, unit
// normal (world, outward as F's gradient, or as the GPU blended it).
struct SlimPixels {
  int width = 0, height = 0;
  std::vector<std::uint8_t> covered;
  std::vector<float> depth;
  std::vector<Vec3> normal;
};

// The reference: every slim occluder of `scene` ray cast per pixel, the
// nearest hit kept (other occluders are not drawn). threads <= 0: all cores.
// samples > 1: coverage still from the pixel's centre ray, depth and normal
// the mean over samples x samples rays spread over the pixel (those that
// hit): the pixel-area surface the points' blend estimates.
SlimPixels slim_reference(const Scene& scene, const Camera& cam, int threads = 0, int samples = 1);

// The GPU's surface from the slim_surface target (unit normal, view depth;
// RGBA float, top-down, as FrameOptions::read_targets returns it): covered
// where the normal is not zero.
SlimPixels slim_from_surface(const std::vector<float>& surface, int width, int height);

struct SlimErrors {
  std::int64_t reference_pixels = 0;  // covered by the reference
  std::int64_t holes = 0;             // covered by the reference, not by the points
  std::int64_t interior_holes = 0;    // holes whose 3x3 neighbourhood the reference covers
  std::int64_t spurious = 0;          // covered by the points, not by the reference
  std::int64_t spurious_far = 0;      // spurious with no covered reference pixel among its 8 neighbours
  std::int64_t compared = 0;          // covered by both, and the same part of the surface
  std::int64_t occluded = 0;          // covered by both, depths apart more than 10% of the size
  double depth_mean = 0.0;  // |GPU - reference| view depth over `compared`, in units of size / 10
  double depth_p99 = 0.0;
  double depth_max = 0.0;
  double normal_mean_deg = 0.0;
  double normal_p99_deg = 0.0;
  double normal_max_deg = 0.0;
  // The same over the interior: compared pixels whose 3x3 neighbourhood both
  // cover (the outline's pixels average a surface turning away within them).
  std::int64_t interior = 0;
  double interior_normal_p99_deg = 0.0;
  double interior_depth_p99 = 0.0;
  // Creases: compared interior pixels where the reference's normal turns by
  // more than 30 degrees to a neighbour (fandisk's edges); the normal error
  // there shows whether the points keep the edge sharp.
  std::int64_t crease_pixels = 0;
  double crease_normal_mean_deg = 0.0;
};

// `size`: the model's size (its bounding box diagonal); depths are reported
// at the model scaled to size 10 (as SLIM fitting tools report errors).
SlimErrors compare_slim(const SlimPixels& gpu, const SlimPixels& ref, double size);

}  // namespace beamcast
