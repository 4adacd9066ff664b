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
// Cells per brick edge of the empty-space grid.
inline constexpr int kBrickCells = 8;

// The occupancy of each brick (x fastest): 1 where the transfer table's
// opacity is non-zero anywhere between the brick's smallest and largest
// value (over the table texels the GPU's linear filter can blend there),
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

 private:
  struct Entry {
    std::weak_ptr<const VolumeGrid> grid;
    const VolumeGrid* grid_id = nullptr;
    int level = 0;
    VolumePyramid pyramid = VolumePyramid::kAverage;
    std::vector<float> transfer;
    std::shared_ptr<const VolumeTextures> textures;
  };
  std::size_t max_entries_;
  std::list<Entry> entries_;  // most recently used first
};

class VolumeResources {
 public:
  // `cache` may be null (everything uploaded for this scene alone).
  VolumeResources(const Scene& scene, VolumeTextureCache* cache);
  struct Uploaded {
    const Volume* volume = nullptr;
    Vec3 spacing{};  // world spacing at the uploaded level (grid convention kept)
    std::shared_ptr<const VolumeTextures> gpu;
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

std::unique_ptr<Pass> make_volume_pass();

}  // namespace beamcast
