// A participating medium filling the scene (issue 15; docs/media.md): its
// coefficients, its phase function and the accuracy knobs of what the
// renderer does with it. Parsed from the scene's "medium" object.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include "protocol/media/regions.hpp"
#include "protocol/vec.hpp"


namespace beamcast {

namespace json_read {
struct Node;
}  // namespace json_read
struct SceneLoadOptions;

// k of the Schlick lobe that approximates a Henyey-Greenstein lobe of mean
// cosine g: k = 1.55 g - 0.55 g^3 (Blasi, Le Saec and Schlick 1993). It
// reaches 1 at g = 0.938 (and peaks at 1.0015 near g = 0.97), so only
// |g| <= kSchlickMaxG gives a valid |k| < 1.
inline constexpr double kSchlickMaxG = 0.93;
double schlick_k_from_g(double g);

// How a beam's piece of the view ray is integrated through the medium
// (render: shaders/beam_math.glsl, CPU: render/beam_medium.hpp).
enum class BeamMediumRule : unsigned char {
  // Each sub-piece of the piece by a two-node Gauss rule whose weight is the
  // density itself (nodes and weights from the moments of f, a table per
  // density), the attenuation evaluated exactly at the nodes.
  kGauss2,
  // The density's integral over each sub-piece attenuated at the
  // sub-piece's midpoint (the simple form; for comparison).
  kMidpoint,
};

// How the volume photons' in-scattered light along a view ray is estimated
// (pass "volume_photons", shaders/volume_splat.frag).
enum class VolumeEstimator : unsigned char {
  // The beam radiance estimate: each photon's sphere kernel (radius r)
  // integrated along the visible part of the ray (clipped by the near plane
  // and the surface), attenuated exactly within it.
  kBeam,
  // The seed's: each photon's whole contribution from the point of the view
  // ray nearest to it, attenuated from there to the eye, over the disk of
  // radius r about the photon facing the camera.
  kSeed,
  // No splats (issue 39, item 5): the photons binned into a world-space
  // grid each frame (their phase towards the eye summed per cell, a
  // compute pass), and each pixel's view ray marched through it
  // (trilinear), attenuated exactly per step (pass "volume_grid",
  // render/volume_grid.hpp). Costs photons + pixels x steps, not photons x
  // covered pixels.
  kGrid,
};

struct Medium {
  // Per unit of scene length; the medium fills all of space, so a ray that
  // meets no surface sees the background through an infinite optical depth
  // (none of it) once sigma_t > 0.
  double sigma_s = 0.0;  // scattering
  double sigma_a = 0.0;  // absorption
  double k = 0.0;        // Schlick phase parameter (gi/phase.hpp's convention; > 0 forward)
  BeamMediumRule beam_rule = BeamMediumRule::kGauss2;
  // Largest optical depth of one sub-piece of a beam's piece (the pieces
  // are split into ceil(depth / beam_step) sub-pieces, at most
  // kMaxBeamSubPieces); the error falls as beam_step^4 (docs/media.md).
  double beam_step = 1.0;
  VolumeEstimator estimator = VolumeEstimator::kGrid;
  // The volume photons' kernel radius; 0: about 50 photons per kernel sphere
  // for the stored photons spread evenly through the scene's bounding box
  // (default_volume_radius, gi/photon_map.hpp).
  double radius = 0.0;
  // The alternative to photon LOD (gi.lod): a cap on a volume photon's
  // kernel radius on screen, in pixels (0: none). Photons nearer the camera
  // than where their kernel would exceed it get a kernel that just does
  // (normalized to it: the estimate stays unbiased, noisier there), so each
  // photon costs at most ~4 cap^2 fragments; none is dropped.
  double radius_pixels = 0.0;
  // The seed's S (section 5.7): the volume photons' attenuation by the
  // regions ("media") taken not where each photon's light leaves the view
  // ray but at the centre of the one of S equal segments of the ray's
  // visible part that holds that point. 0: exactly there (the default).
  // Only the regions' optical depth is quantized; the scene-wide medium's
  // is exact either way, as in the seed's homogeneous case.
  int segments = 0;

  double sigma_t() const { return sigma_s + sigma_a; }
};

// A region of heterogeneous medium (seed 001 section 5.7; "media" in JSON):
// its own coefficients inside its shape (a kind of RegionShape,
// protocol/media/: an axis-aligned box, a sphere, a closed triangle mesh),
// added to the scene-wide medium and to any region it overlaps (the seed's
// fig 5.6: where A and B overlap, sigma = sigma_A + sigma_B). Each function
// of the shape is std::visit over its kinds.
struct MediumRegion {
  RegionShape shape;
  double sigma_s = 0.0;
  double sigma_a = 0.0;
  double k = 0.0;
  double sigma_t() const { return sigma_s + sigma_a; }
  Aabb bounds() const;
  bool contains(const Vec3& x) const;
  // The length of o + t v (|v| = 1), t in [t0, t1], inside the region.
  double chord(const Vec3& o, const Vec3& v, double t0, double t1) const;
  // The ray parameter where o + t v (t >= 0) last leaves the region; -1 if
  // it never is inside.
  double exit(const Vec3& o, const Vec3& v) const;
  // Appends the ray parameters in (0, t_end) where o + t v crosses the
  // region's boundary (a convex kind: where it enters and leaves).
  void crossings(const Vec3& o, const Vec3& v, double t_end, std::vector<double>* out) const;
  // Its record for shaders/medium_regions.glsl and the triangles it puts in
  // the shader's SSBO (none but a mesh's).
  RegionGpu gpu() const;
  RegionTriangles gpu_triangles() const;
};

// Regions per scene (the shaders hold them in uniform arrays of this size).
inline constexpr int kMaxMediumRegions = 16;

// The scene-wide medium and the regions together: coefficients at a point,
// optical depth along a segment (exact: chords of boxes and spheres), and
// the majorant extinction for delta tracking. Either may be absent.
class MediumField {
 public:
  MediumField(const Medium* global, const std::vector<MediumRegion>& regions);
  bool empty() const { return majorant_ <= 0.0; }
  bool homogeneous() const { return regions_->empty(); }
  double sigma_t(const Vec3& x) const;
  double sigma_s(const Vec3& x) const;
  // The phase parameter at x: the scattering-weighted mean of the k of
  // the global medium and the regions containing x.
  double k(const Vec3& x) const;
  double optical_depth(const Vec3& o, const Vec3& v, double t0, double t1) const;
  double majorant() const { return majorant_; }
  // A free path from o along v (|v| = 1): the t at which the optical depth
  // from o reaches `tau` (an exponential sample, -log(1 - u)), or +inf if
  // that is not before t_end. Sampled exactly, segment by segment between
  // the regions' boundaries (the field is constant on each), so the cost
  // is bounded by the boundaries crossed (at most 2 per box or sphere and
  // the crossings of each mesh), never by the ratio of the majorant to the
  // local extinction (delta tracking's rejection loop, which a region of
  // sigma 1e6 in fog of 1e-300 made endless: issue 43). The scene-wide
  // medium ends at kMediumExtent: a path that reaches it has left.
  double free_path(const Vec3& o, const Vec3& v, double t_end, double tau) const;
  // Beyond this ray parameter o + t v meets no medium: infinite with the
  // scene-wide medium, else the last exit from a region (-1: none).
  double last_exit(const Vec3& o, const Vec3& v) const;

 private:
  const Medium* global_;
  const std::vector<MediumRegion>* regions_;
  double majorant_ = 0.0;
};

// Where the scene-wide medium ends for photons and paths: the cube |x_i| <=
// 1e12 (the default max_abs_coordinate), so every free path ends at a
// finite point that Embree (floats, |x| <= 1.8e18) can still take.
inline constexpr double kMediumExtent = 1e12;

// The most sub-pieces a beam's piece is split into; with optical depth
// beyond kMaxBeamSubPieces x beam_step the rest of the piece is attenuated by
// e^-32 or more (at the default step), below any pixel's resolution.
inline constexpr int kMaxBeamSubPieces = 32;

// The fields of "medium", for `hello`'s capabilities (a region's:
// medium_region_fields, protocol/media/regions.hpp).
inline constexpr std::string_view kMediumFields[] = {
    "sigma_s", "sigma_a",   "k",      "g",
    "beam_rule", "beam_step", "estimator", "radius", "radius_pixels", "segments"};

// Throws ProtocolError (code, message, JSON path) for a bad field: negative
// coefficients, |k| >= 1 or |g| > kSchlickMaxG, both k and g.
Medium parse_medium(const json_read::Node& n);
// One entry of "media": its kind by "type" (parse_region_shape, each
// kind's parse: coordinates and radii bounded by the limits'
// max_abs_coordinate, a mesh refused unless closed), then its coefficients;
// `mesh_triangles` counts the scene's mesh-region triangles against
// kMaxMediumMeshTriangles.
MediumRegion parse_medium_region(const json_read::Node& n, const SceneLoadOptions& opts,
                                 std::int64_t* mesh_triangles);

}  // namespace beamcast
