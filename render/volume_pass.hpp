// Scalar volumes (issue 17, seed 004; docs/volumes.md): the GPU side. The
// scene's volumes as 3D textures (16-bit normalized, trilinear, at the
// settings' pyramid level) with their transfer functions as 1D textures
// (group "volumes"), and the pass "volumes", which ray casts each volume in
// the fragment shader (shaders/volume_cast.frag) and composites it over hdr,
// the rays ending at the nearest surface (view_depth).
#pragma once

#include <list>
#include <memory>
#include <vector>

#include "protocol/scene.hpp"
#include "render/gl_util.hpp"

namespace beamcast {

class Pass;

// Texels of each transfer function's 1D texture: the piecewise linear
// function sampled at i / (kTransferTexels - 1), so GL_LINEAR between texel
// centres reproduces it exactly between those samples (only a knot that
// falls between two samples is rounded off, by at most one sample's width).
inline constexpr int kTransferTexels = 1024;
// Entries per axis of a pre-integration table (front value x back value,
// each i / (N - 1)); docs/volumes.md measures its size.
inline constexpr int kPreintegrationTexels = 256;
// Cells per brick edge of the empty-space grid.
inline constexpr int kBrickCells = 8;

// The occupancy of each brick (x fastest): 1 where the transfer table's
// opacity is non-zero anywhere between the brick's smallest and largest
// value (over the table texels the GPU's linear filter can blend there, the
// range first widened to the pre-integration table's entries around it),
// exposed for tests.
std::vector<std::uint8_t> brick_occupancy(const VolumeGrid& grid, const std::vector<float>& texels,
                                          std::array<int, 3>* brick_dims);

// One volume on the GPU at one pyramid level with one transfer table.
struct VolumeTextures {
  std::array<int, 3> dims{0, 0, 0};  // of the uploaded level
  GlTexture values;                  // GL_R16, 3D
  GlTexture transfer;                // GL_RGBA32F, 1D: (colour x intensity, log2(1 - opacity))
  // Empty-space skipping: per brick of kBrickCells^3 cells, 1 if any value
  // in it (its corner voxels included) has a non-zero opacity in the
  // transfer table, else 0 (GL_R8UI, 3D, nearest).
  GlTexture bricks;
  std::array<int, 3> brick_dims{0, 0, 0};
  bool any_empty = false;  // some brick is empty (else the pass does not test them)
};

// The volumes' textures across frames (a renderer's, like its TableCache):
// keyed by the grid (the same shared grid: a stored scene's, its camera
// overrides', the preview's levels), the pyramid level and rule, and the
// transfer table, least recently used evicted first. Uploading a 256^3
// volume and its brick grid takes about 100 ms on llvmpipe; a preview frame
// must not pay it again.
class VolumeTextureCache {
 public:
  explicit VolumeTextureCache(std::size_t max_entries = 4) : max_entries_(max_entries) {}
  std::shared_ptr<const VolumeTextures> get(const Volume& volume, const VolumeSettings& settings);
  // The pre-integration table of `volume`'s transfer function for steps of
  // `step` (GL_RGBA32F, 2D, linear), kept for the last few (transfer
  // function, intensity, step): the preview's levels each have their own step.
  std::shared_ptr<const GlTexture> preintegration(const Volume& volume, double step);
  // Frees the textures of volumes whose scene is gone (get() would only
  // drop them at its next call); with the context current.
  void drop_unused();

 private:
  struct Entry {
    std::weak_ptr<const VolumeGrid> grid;
    const VolumeGrid* grid_id = nullptr;
    int level = 0;
    VolumePyramid pyramid = VolumePyramid::kAverage;
    std::vector<float> transfer;
    std::shared_ptr<const VolumeTextures> textures;
  };
  struct Table {
    TransferFunction transfer;
    double intensity = 1.0;
    double step = 0.0;
    std::shared_ptr<const GlTexture> texture;
  };
  std::size_t max_entries_;
  std::list<Entry> entries_;  // most recently used first
  std::list<Table> tables_;   // most recently used first
};

class VolumeResources {
 public:
  // `cache` may be null (everything uploaded for this scene alone).
  VolumeResources(const Scene& scene, VolumeTextureCache* cache);
  struct Uploaded {
    const Volume* volume = nullptr;
    Vec3 spacing{};  // world spacing at the uploaded level (grid convention kept)
    std::shared_ptr<const VolumeTextures> gpu;
    // The pre-integration table for this level's step (null with point
    // sampling).
    std::shared_ptr<const GlTexture> preintegration;
  };
  const std::vector<Uploaded>& volumes() const { return volumes_; }

 private:
  std::vector<Uploaded> volumes_;
};

// u_volume_lo / u_volume_hi of shaders/volume_knots.glsl: the box around the
// scene's volumes relative to view `view`'s eye (-1: the only camera).
class ProgramPair;
struct FrameContext;
void set_volume_box(ProgramPair& program, bool multiview, const FrameContext& ctx, int view);

// The RGBA texels of a transfer function (colour x intensity, log2(1 - opacity)),
// exposed for tests.
std::vector<float> transfer_texels(const Volume& volume);

// The pre-integration table of a transfer function for steps of length
// `step` (world units): kPreintegrationTexels^2 RGBA texels, front value
// i / (N - 1) along x, back value j / (N - 1) along y, each holding what a
// step whose value runs linearly from front to back adds: its colour
// (x intensity, already weighted by its opacity and attenuated within the
// step) and log2 of its transmittance. The transmittance is exact for a
// linear value: 2^-(L mean lambda), lambda(v) = -log2(1 - opacity(v)) /
// opacity_unit averaged over [front, back]. The colour is the integral of
// c sigma over the step, sigma = lambda ln 2, scaled by alpha / tau (the
// step's opacity over its optical depth): exact for a constant value (where
// it is c alpha, the point sample's), and otherwise the attenuation inside
// the step taken as spread evenly (docs/volumes.md measures what that
// costs). The integrals of lambda and c sigma come from the piecewise
// linear transfer function by the trapezoid rule on 16 points a table cell,
// in double.
std::vector<float> preintegration_texels(const Volume& volume, double step);

// Whether the pass pre-integrates: asked for, and with opacity correction
// (the parser refuses pre-integration without it; settings made in code
// fall back to point samples).
inline bool preintegrated(const VolumeSettings& s) {
  return s.integration == VolumeIntegration::kPreintegrated && s.opacity_correction;
}

// The "volumes" pass; knots: the row of scenes with beams, which also
// writes volume_t0/volume_t1.
std::unique_ptr<Pass> make_volume_pass(bool knots);

}  // namespace beamcast
