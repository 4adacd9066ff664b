// Scalar volumes ray cast with a transfer function (seed 004, issue 17;
// docs/volumes.md). GL-free: the scene parser, the GPU pass's packing and the
// CPU reference all read this model.
//
// Grid convention (the GPU's and the reference's): voxel (i, j, k), i fastest
// in memory, has its centre at grid coordinate (i, j, k); the volume's box
// spans grid coordinates [0, n - 1] on each axis (voxel centre to voxel
// centre), so a GL texture coordinate is (g + 0.5) / n. Between centres the
// value is trilinear (GL_LINEAR); outside the box there is no volume.
// World from grid: world = origin + R (g * spacing), R the rotation about the
// origin.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/vec.hpp"

namespace beamcast {

struct SceneLoadOptions;
namespace json_read {
struct Node;
}

// Where a volume's voxels come from ("source": {"type": ...}).
enum class VolumeSourceType : std::uint8_t {
  kRaw,            // headerless file: dimensions, sample type, byte order given in the scene
  kNrrd,           // NRRD (attached header; raw or gzip encoding)
  kInr,            // INRIA .inr (256-byte-multiple header; .inr.gz too)
  kFile,           // a file in another format of the volume-format table
                   // (protocol/volume_formats/; Volume::file names the file)
  kMarschnerLobb,  // the Marschner-Lobb test signal sampled on [-1, 1]^3 (analytic)
  kHeat,           // a dense smooth field (the seed's heat cube): heat spreading from a
                   // few sources, analytic
};

// The voxels, normalized to the transfer function's domain: a stored value q
// means q / 65535 in [0, 1] (the volume's `range` mapped to [0, 1], clamped).
// 16 bits: exact for 8- and 16-bit data, 1.5e-5 steps for float data. Shared
// between copies of a scene (the server's store, requests that override
// cameras).
struct VolumeGrid {
  std::array<int, 3> dims{0, 0, 0};   // x (fastest), y, z; each >= 2
  std::vector<std::uint16_t> values;  // dims[0] * dims[1] * dims[2]
  double value(int i, int j, int k) const {
    return values[(static_cast<std::size_t>(k) * dims[1] + j) * dims[0] + i] / 65535.0;
  }
  std::int64_t voxels() const { return std::int64_t{dims[0]} * dims[1] * dims[2]; }
};

// One control point of a 1D transfer function: at normalized value `value`
// the sample emits `color` (linear RGB, per unit opacity) with `opacity`.
struct TransferPoint {
  double value = 0.0;  // in [0, 1], strictly increasing along the list
  Color color{1.0, 1.0, 1.0};
  double opacity = 0.0;  // in [0, 1]: the opacity of a slab `opacity_unit` thick
  bool operator==(const TransferPoint&) const = default;
};

struct TransferFunction {
  std::vector<TransferPoint> points;  // >= 2, sorted, first at 0 and last at 1 (or clamped)
  // The thickness (world units) of a slab whose opacity is each point's
  // `opacity` (VTK's "scalar opacity unit distance"): a step ds gets
  // alpha(ds) = 1 - (1 - opacity)^(ds / opacity_unit) (opacity correction).
  double opacity_unit = 0.1;
  // Piecewise linear between points, clamped outside them.
  Color color(double v) const;
  double opacity(double v) const;
  bool operator==(const TransferFunction&) const = default;
};

struct Volume {
  VolumeSourceType source = VolumeSourceType::kMarschnerLobb;
  std::shared_ptr<const VolumeGrid> grid;
  Vec3 origin{0.0, 0.0, 0.0};   // world position of voxel (0, 0, 0)'s centre
  Vec3 spacing{1.0, 1.0, 1.0};  // world distance between voxel centres, per axis
  std::array<double, 4> rotation{1.0, 0.0, 0.0, 0.0};  // unit quaternion (w, x, y, z) about origin
  double intensity = 1.0;  // emission scale (the colour's radiance per unit opacity)
  TransferFunction transfer;
  // The data values mapped to 0 and 1 (the grid's normalization; exact()
  // normalizes the analytic fields by it too).
  std::array<double, 2> range{0.0, 1.0};
  std::string file;  // the source file as the scene names it; empty for procedural sources

  // Continuous grid coordinates of a world point, and back.
  Vec3 to_grid(const Vec3& world) const;
  Vec3 to_world(const Vec3& grid) const;
  // The world-space box's 8 corners' bounds (axis-aligned, for culling).
  void world_bounds(Vec3* lo, Vec3* hi) const;
  // Trilinear value at continuous grid coordinates inside [0, n - 1]^3 (GL_LINEAR
  // with texel centres at integers; clamped at the faces).
  double sample(const Vec3& g) const;
  // The field the grid samples, where it is known exactly (Marschner-Lobb,
  // heat: analytic, normalized as the grid is); the trilinear sample otherwise.
  double exact(const Vec3& g) const;
};

// The ray caster's accuracy knobs ("volume" in JSON), the seed's S_z, R_v and
// early ray termination, measured in docs/volumes.md.
enum class VolumePyramid : std::uint8_t { kAverage, kMax, kNonZero };
// How a step's colour and opacity come from the transfer function: at one
// point of the step (the seed's way), or pre-integrated (Engel, Kraus and
// Ertl 2001): the step's integral with the value taken as linear between its
// two ends, looked up in a 2D table of (front value, back value) made for
// the step's length (render/volume_pass.hpp, docs/volumes.md).
enum class VolumeIntegration : std::uint8_t { kPoint, kPreintegrated };
struct VolumeSettings {
  // S_z: samples per voxel spacing along a ray (the step is the smallest
  // spacing over this; at R_v level L, 2^L times the spacing).
  double samples_per_voxel = 2.0;
  // alpha' = 1 - (1 - alpha)^(ds / opacity_unit); off: the seed's alpha per
  // sample whatever the step (too transparent when coarse).
  bool opacity_correction = true;
  // A ray stops once its opacity reaches this (1: never, no early termination).
  double ert_threshold = 0.99;
  // Ray starts offset by a per-pixel fraction of a step (no wood-grain rings).
  bool jitter = true;
  // Empty-space skipping: the march leaps over bricks of 8^3 voxel cells
  // whose values all map to zero opacity (a min/max grid; exact: it skips
  // only samples that would add nothing).
  bool skip_empty = true;
  // R_v: pyramid level of the volume (0: full resolution; each level halves
  // every axis) and how a level's voxel is made from the 8 below.
  int level = 0;
  VolumePyramid pyramid = VolumePyramid::kAverage;
  // Pre-integration needs opacity correction (its table is made for the
  // step's length): with "opacity_correction": false the default is kPoint,
  // and asking for both is refused.
  VolumeIntegration integration = VolumeIntegration::kPoint;
};

// The analytic fields of the procedural sources on [-1, 1]^3, in [0, 1].
// Marschner-Lobb with alpha 0.25, f_M 6:
// rho = ((1 - sin(pi z / 2)) + alpha (1 + cos(2 pi f_M cos(pi r / 2)))) / (2 (1 + alpha)),
// r = sqrt(x^2 + y^2).
double marschner_lobb(double x, double y, double z);
// Heat from four point sources spread by diffusion (heat kernels without
// their constant factor, folded into the weights) over a floor of 0.05, so
// every voxel is non-zero, like the seed's dense "poisson" cube:
// h = 0.05 + sum_i w_i exp(-|p - c_i|^2 / s_i), s_i = 4 D t_i; the sources
// (c_i, s_i, w_i) are listed in volume.cpp. On [-1, 1]^3 h lies in
// (0.05, 0.91): its one maximum, 0.9097, is near (-0.26, -0.17, -0.16).
double heat_field(double x, double y, double z);

// A procedural source's grid: the field sampled at the n^3 voxel centres,
// voxel i at field coordinate -1 + 2 i / (n - 1) on each axis, normalized by
// `range` (the data value mapped to 0 and 1) and rounded to 16 bits. Volume::exact
// evaluates the same expression, so the two agree at voxel centres to within
// half a 16-bit step.
std::shared_ptr<const VolumeGrid> procedural_grid(VolumeSourceType type, int n,
                                                  std::array<double, 2> range = {0.0, 1.0});
// A procedural volume as the scene format makes it by default: n^3 voxels
// filling [-1, 1]^3, range [0, 1], transfer preset `preset` with opacity
// unit 0.1 (a twentieth of the box's side).
Volume procedural_volume(VolumeSourceType type, int n, std::string_view preset = "grey");

// The transfer presets by name ("grey", "bone", "ml"; docs/scene-format.md,
// "Volumes"); nullopt for another name. The opacity unit is left at 0.1.
std::optional<TransferFunction> transfer_preset(std::string_view name);

// The R_v pyramid. Each level halves every axis: n' = max(2, ceil(n / 2)).
// Voxel I of a level is made from voxels 2I and 2I + 1 of the level below on
// each axis (those that exist: the last voxel of an odd axis has one; an
// axis of 2 stays as it is, voxel I from voxel I), so from at most 8 voxels,
// by `how`: their average, their maximum, or the average of the non-zero
// ones (0 if all are 0), rounded to the nearest 16-bit value (halves up).
// Level 0 is a copy of g. Volume::exact maps grid coordinates to the field
// by its grid's dims: keep the level-0 grid in a Volume that calls it.
std::array<int, 3> volume_level_dims(const std::array<int, 3>& dims, int level);
std::shared_ptr<const VolumeGrid> volume_level(const VolumeGrid& g, int level, VolumePyramid how);

// Bounds of the scene format (docs/scene-format.md, "Volumes").
inline constexpr int kMaxVolumes = 8;  // volumes per scene
inline constexpr std::int64_t kMaxVolumeVoxels = 64LL
                                                 << 20;  // summed over the scene (2 bytes each)
inline constexpr int kMaxVolumeDimension = 2048;         // voxels per axis
inline constexpr int kMaxTransferPoints = 256;
inline constexpr int kMaxVolumeLevel = 4;  // VolumeSettings::level's largest

// The scene format's names, for the parser and `hello`'s capabilities.
inline constexpr std::string_view kVolumeFields[] = {"source", "origin",   "spacing",  "rotation",
                                                     "range",  "transfer", "intensity"};
// The fields of each source type besides "type": raw; the file formats
// (protocol/volume_formats/); marschner_lobb and heat.
inline constexpr std::string_view kVolumeRawFields[] = {"file", "dimensions", "format", "endian"};
inline constexpr std::string_view kVolumeFileFields[] = {"file"};
inline constexpr std::string_view kVolumeProceduralFields[] = {"resolution"};
inline constexpr std::string_view kVolumeRawFormats[] = {"uint8", "uint16", "float32"};
inline constexpr std::string_view kVolumeTransferFields[] = {"preset", "points", "opacity_unit"};
inline constexpr std::string_view kVolumeTransferPresets[] = {"grey", "bone", "ml"};
inline constexpr std::string_view kVolumeSettingFields[] = {
    "samples_per_voxel", "opacity_correction", "ert", "jitter", "skip_empty", "level",
    "pyramid",           "integration"};
inline constexpr std::string_view kVolumePyramids[] = {"average", "max", "nonzero"};
inline constexpr std::string_view kVolumeIntegrations[] = {"point", "preintegrated"};

// One entry of "volumes" (docs/scene-format.md, "Volumes"): its source (a
// file below the options' assets directory, refused outside it as meshes
// are, or a procedural field), placement, range, transfer function and
// intensity. `voxels` counts the scene's voxels against kMaxVolumeVoxels,
// checked before anything is allocated. Throws ProtocolError with the JSON
// pointer of the bad field (for a bad file, its "file").
Volume parse_volume(const json_read::Node& n, const SceneLoadOptions& opts, std::int64_t* voxels);
// The source types: "raw", the file formats' names (the volume-format
// table's rows), "marschner_lobb", "heat".
std::vector<std::string_view> volume_source_types();
// The scene's "volume" object.
VolumeSettings parse_volume_settings(const json_read::Node& n);

}  // namespace beamcast
