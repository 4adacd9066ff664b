// The pass graph, GL-free: one catalog of passes, each declaring when a frame
// needs it, the named targets it reads and writes and the per-scene data it
// uploads. A frame's plan (the passes that run, the targets they need, the
// uploads) is derived from those declarations alone, so the server can report
// it, tests can check it without a GL context, and the renderer runs exactly
// what the plan lists (each catalog row makes its executor).
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/scene.hpp"

namespace beamcast {

// True if a light with `points` direct points has them shared out over the
// 2 x 2 pixel pattern (gi.direct_interleave 4 and a nonzero multiple of 4).
bool interleaves_direct_points(const GiSettings& gi, std::size_t points);
// True if any light of the scene does (pass direct with the split target,
// which gi_resolve filters).
bool interleaves_direct(const Scene& scene);

// Every render target a pass can read or write (target_catalog() declares
// each one's format, size and start value). Passes name targets by these
// enumerators, so a misspelt target does not compile.
enum class TargetId {
  kHdr,
  kViewDepth,
  kDepth,
  kOutput,
  kUpscaled,
  kGbNormal,
  kGbAlbedo,
  kGiIndirect,
  kSlimNear,
  kSlimRadius,
  kSlimZbuf,
  kSlimSumAlbedo,
  kSlimSumField,
  kSlimSumWeight,
  kSlimSumField2,
  kSlimSumWeight2,
  kSlimSurface,
  kVolumeT0,
  kVolumeT1,
  kDirectSplit,
  kSpecular,
};
inline constexpr std::size_t kTargetCount = static_cast<std::size_t>(TargetId::kSpecular) + 1;

// The per-scene data a pass needs uploaded before the frame (SceneResources
// makes each group the plan lists, in this order).
enum class UploadGroup {
  kBeams,          // tables, beam instances
  kOccluders,      // triangles, analytic occluders
  kPhotons,        // the surface photon maps (traced unless cached)
  kVolumePhotons,  // the medium's scattering events as splats
  kVolumeGrid,     // the same events for the world grid
  kShadows,        // direct points and their shadow maps
  kSlim,           // SLIM surfaces
  kVolumes,        // scalar volumes' textures
  kSpecular,       // mirror and glass rays (CPU or GPU tracer)
};
// The group's name in messages and documents ("volume_photons").
const char* upload_group_name(UploadGroup g);

class Pass;  // an executor (render/passes.hpp); GL, so only named here
// Makes a pass's executor; called with a GL context current. Captureless
// lambdas convert to it, so a catalog row can pick an executor's variant.
using PassFactory = std::unique_ptr<Pass> (*)();

// The texel layout of a kSplat target. llvmpipe rasterizes a framebuffer in
// 64 x 64 tiles, one thread a tile: a splat grid of one tile (64 x 64 at
// 512^2 and splat_scale 8) would be splatted by one thread however many
// the machine has (the photon pass ran as fast with LP_NUM_THREADS=1). So
// a grid of fewer than kSplatTiles tiles is stored as `bands` horizontal
// bands of `band_h` rows side by side, each starting on a tile column
// (`stride` texels apart): grid texel (x, y) is stored at
// (x + (y / band_h) * stride, y % band_h). The passes that draw into it draw
// once per band (viewport shifted, scissor on the band); the reader,
// gi_resolve.frag's corrected(), maps with the same formula. One band is
// the plain layout; a GPU gains nothing from bands and loses nothing.
struct SplatBands {
  int w = 0, h = 0;  // the grid, in splat pixels
  int bands = 1;
  int band_h = 0;
  int stride = 0;
  int texture_w() const { return (bands - 1) * stride + w; }
};
inline constexpr int kLlvmpipeTile = 64;
inline constexpr int kSplatTiles = 4;
// The fewest bands whose tiles (tile columns a band x bands x tile rows a
// band) reach kSplatTiles, bands of at least 8 rows (each band costs a
// draw's vertices and binning).
inline SplatBands splat_bands(int w, int h) {
  auto tiles = [](int n) { return (n + kLlvmpipeTile - 1) / kLlvmpipeTile; };
  SplatBands b{w, h, 1, h, 0};
  for (int n = 1; n <= std::max(1, h / 8); ++n) {
    b.band_h = (h + n - 1) / n;
    b.bands = (h + b.band_h - 1) / b.band_h;
    if (tiles(w) * b.bands * tiles(b.band_h) >= kSplatTiles) break;
  }
  if (b.bands > 1) b.stride = tiles(w) * kLlvmpipeTile;
  return b;
}

// Views in one multi-view batch: the size of the shaders' camera array
// (BEAMCAST_MAX_VIEWS in shaders/multiview*.glsl; 64 blocks of 176 bytes fit
// the 16 KiB every GL 4.5 driver must allow a uniform block).
inline constexpr int kMaxBatchViews = 64;

// Pixel formats of targets (the GL side maps them to internal formats).
enum class TargetFormat {
  kRgba32f,  // linear HDR colour
  kR32f,     // one float (view depth)
  kDepth32f, // depth buffer, reversed Z
  kDisplay,  // RGBA8 or RGBA16, per the scene's output bit depth
};
// What a target holds at frame start (before any pass writes it).
enum class TargetClear {
  kNone,        // nothing: a pass must write it before another reads it
  kBackground,  // the scene's background colour
  kNoSurface,   // FrameTargets' kNoSurface view depth ("no surface on this ray")
  kFarDepth,    // reversed-Z far plane (0)
  kZero,        // zero (accumulation targets)
  kOne,         // one (products: transmittance)
};
enum class TargetSize {
  kRender,  // the render size (camera size times the resolution scale)
  kCamera,  // the camera's own size (what the client asked for)
  kSplat,   // the render size over FramePlan::splat_scale (rounded up)
};

struct TargetDecl {
  TargetId id{};
  std::string name;  // in messages
  TargetFormat format = TargetFormat::kRgba32f;
  TargetSize size = TargetSize::kRender;
  TargetClear clear = TargetClear::kNone;
};

// What a plan is derived from: the scene and the frame's options.
struct PlanInput {
  const Scene& scene;
  double resolution_scale = 1.0;  // < 1: rendered smaller, then upscaled
  bool scaled() const { return resolution_scale > 0.0 && resolution_scale < 1.0; }
};

// One row of the pass catalog (render/pass_catalog.cpp): when a frame needs
// the pass, what it reads and writes, what it uploads, and its executor.
struct PassDecl {
  std::string name;  // as reported in `passes` and pass_ms
  bool (*needed)(const PlanInput& in) = nullptr;
  std::vector<TargetId> reads;           // must hold data (cleared or written earlier)
  std::vector<TargetId> optional_reads;  // used only if a planned pass writes them
  // Colour targets in attachment order (fragment output locations), then at
  // most one depth target.
  std::vector<TargetId> writes;
  std::vector<UploadGroup> uploads;  // per-scene data (SceneResources)
  PassFactory make = nullptr;        // null only in the plan tests' own catalogs
};

// Broken pass declarations: a required read nobody provides, a target
// missing from the target catalog. A programming error, never a client's.
class PlanError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

struct FramePlan {
  std::vector<const PassDecl*> passes;  // execution order
  std::vector<const TargetDecl*> targets;  // read or written by a planned pass, allocated
  std::vector<UploadGroup> uploads;        // union of the planned passes' uploads
  TargetId final_target = TargetId::kOutput;  // the last pass's first write: what is read back
  int splat_scale = 1;  // kSplat targets' divisor: the scene's gi.splat_scale (0: auto_splat_scale)
  // The largest divisor auto_splat_scale may pick: 2 when a caustic map is
  // drawn (its disks, a quarter of the global radius, fall between the
  // texels of a coarser grid: the caustic region read 20% bright at 4,
  // docs/gi.md "Caustics and the splat size"), else no cap.
  int auto_splat_cap = 1 << 30;

  // True if a planned pass (not just the frame-start clear) writes `target`.
  bool written(TargetId target) const;
  bool uses(TargetId target) const;
  bool uploads_group(UploadGroup group) const;
  std::vector<std::string> names() const;
};

// The built-in targets, one per TargetId in its order (render/pass_plan.cpp).
const std::vector<TargetDecl>& target_catalog();
// The built-in passes in execution order, each with its executor: defined in
// render/pass_catalog.cpp (the GL library, beside the executors it makes),
// the one file a new pass adds a row to.
const std::vector<PassDecl>& pass_catalog();

// The plan of one frame; it points into `catalog` and `targets`, which must
// outlive it (the built-in catalogs are static). Throws PlanError if the declarations are inconsistent
// for the passes this input plans (a required read of a target that is neither
// cleared at frame start nor written by an earlier planned pass, or a target
// missing from `targets`).
FramePlan make_plan(const PlanInput& in, const std::vector<PassDecl>& catalog = pass_catalog(),
                    const std::vector<TargetDecl>& targets = target_catalog());

// The names of the passes a frame of `scene` runs, in execution order
// (render/pass_catalog.cpp).
std::vector<std::string> plan_passes(const Scene& scene, double resolution_scale = 1.0);

}  // namespace beamcast
