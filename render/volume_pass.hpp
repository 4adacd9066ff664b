// Scalar volumes (issue 17, seed 004; docs/volumes.md): the GPU side. The
// scene's volumes as 3D textures (16-bit normalized, trilinear, at the
// settings' pyramid level) with their transfer functions as 1D textures
// (group "volumes"), and the pass "volumes", which ray casts each volume in
// the fragment shader (shaders/volume_cast.frag) and composites it over hdr,
// the rays ending at the nearest surface (view_depth).
#pragma once

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

class VolumeResources {
 public:
  explicit VolumeResources(const Scene& scene);
  struct Uploaded {
    const Volume* volume = nullptr;
    std::array<int, 3> dims{0, 0, 0};  // of the uploaded level
    Vec3 spacing{};                    // world spacing at that level (grid convention kept)
    GlTexture values;                  // GL_R16, 3D
    GlTexture transfer;                // GL_RGBA32F, 1D: (colour x intensity, log2(1 - opacity))
    // Empty-space skipping: per brick of kBrickCells^3 cells, 1 if any value
    // in it (its corner voxels included) has a non-zero opacity in the
    // transfer table, else 0 (GL_R8, 3D, nearest).
    GlTexture bricks;
    std::array<int, 3> brick_dims{0, 0, 0};
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
