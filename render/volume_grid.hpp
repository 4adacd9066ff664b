// The volume photons' in-scattered light without splats (issue 39, item 5;
// medium.estimator "grid", the default; docs/media.md, "The grid
// estimate"). Once per scene the volume photons are sorted by the cell of
// a world-space grid that holds them (bin_volume_photons, on the CPU);
// each frame a compute pass (shaders/volume_grid_bin.comp) sums every
// cell's photons' light towards the eye, p(mu) power / cell volume, into a
// 3D texture, and a full-screen pass (shaders/volume_grid.frag) marches
// each pixel's view ray through it (trilinear), attenuating each step
// exactly. The cost is photons + pixels x steps, where the splats'
// (render/medium_pass.hpp) is photons x the pixels their kernels cover.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "gi/photon_map.hpp"
#include "protocol/medium.hpp"
#include "protocol/vec.hpp"
#include "render/gl_util.hpp"

namespace beamcast {

class Pass;

// A cell's side is this many volume kernel radii (medium.radius, or the
// default of ~50 photons per kernel sphere). The trilinear read spreads a
// cell's photons over two cells a side, so a cell of 0.8 r smooths over
// about the kernel's diameter: on fog_stage at 128^2 (docs/media.md) the
// error against the path tracer was least there (0.130; 1.6 r: 0.142,
// 0.4 r: 0.131, the splats 0.127).
inline constexpr double kGridCellPerRadius = 0.8;
// At most this many cells (16 MiB of RGBA32F at level 0): past it the cells
// grow.
inline constexpr std::int64_t kMaxGridCells = std::int64_t{1} << 20;
// Each side a multiple of this, so that the LOD levels (gi.lod) are exact
// 2 x 2 x 2 averages down to level 3.
inline constexpr int kGridSideMultiple = 8;
// The share of the photons left out of the grid's box at each end of each
// axis: a few photons that flew far out in a medium filling space would
// otherwise stretch the grid over empty space.
inline constexpr double kGridOutlierShare = 5e-4;
// And within the box of the occluders and lights, this many times its
// largest side wider each way: in a medium filling space many photons fly
// far out (fog_stage: the grid over all but 0.1% of them had cells of ~2,
// the spot's cone smeared away), where their light is faint and far.
inline constexpr double kGridSceneMargin = 0.5;

struct VolumeGridLayout {
  Vec3 origin{};  // world position of the grid's lower corner
  double cell = 1.0;
  std::array<int, 3> dims{0, 0, 0};
  std::int64_t cells() const {
    return std::int64_t{dims[0]} * dims[1] * dims[2];
  }
};

// One photon as the binning pass reads it (std430, 48 bytes).
struct VolumeGridPhoton {
  float position[4];  // xyz: relative to the grid's origin; w: Schlick k there
  float power[4];     // rgb: flux; w: 0
  float dir[4];       // xyz: travel direction; w: its index in the volume map (uint bits)
};

struct VolumeGridBins {
  VolumeGridLayout layout;
  std::vector<VolumeGridPhoton> photons;  // sorted by cell (x fastest)
  std::vector<std::uint32_t> starts;      // cells + 1: cell c holds [starts[c], starts[c + 1])
  std::size_t dropped = 0;                // photons outside the grid's box (not binned)
};

// Sorts `photons` (the volume map) into the cells of a grid of side
// kGridCellPerRadius * radius over the box that holds them less the
// outliers (kGridOutlierShare) and what lies far outside `scene`
// (kGridSceneMargin; empty: no bound), within kMaxGridCells. No photon: a grid of
// one block of empty cells.
VolumeGridBins bin_volume_photons(const std::vector<Photon>& photons, const MediumField& field,
                                  double radius, const Aabb& scene);

// The grid on the GPU: the sorted photons (SSBO), the cells' starts (SSBO)
// and the 3D texture the binning pass writes (RGBA32F, 4 levels).
class VolumeGridResources {
 public:
  explicit VolumeGridResources(const VolumeGridBins& bins);
  const VolumeGridLayout& layout() const { return layout_; }
  GLuint photon_buffer() const { return photons_.get(); }
  GLuint start_buffer() const { return starts_.get(); }
  GLuint texture() const { return texture_.get(); }
  int levels() const { return levels_; }
  GLsizei photon_count() const { return count_; }
  std::size_t dropped() const { return dropped_; }

 private:
  VolumeGridLayout layout_;
  GlBuffer photons_, starts_;
  GlTexture texture_;
  int levels_ = 1;
  GLsizei count_ = 0;
  std::size_t dropped_ = 0;
};

// The pass "volume_grid".
std::unique_ptr<Pass> make_volume_grid_pass();

}  // namespace beamcast
