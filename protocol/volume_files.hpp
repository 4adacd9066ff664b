// Volume files (issue 17; docs/scene-format.md, "Volumes"): headerless raw
// files read into their stored sample type, and the normalization of any
// file's samples to a VolumeGrid. Files with a header are read by the
// readers of the volume-format table (protocol/volume_formats/: one file per
// format, one row each in volume_formats.cpp). Internal to protocol/:
// volume_json.cpp calls these. Every failure is a ProtocolError at the JSON
// pointer of the scene's "file" field (or the field named), code
// "bad_volume" for what is wrong inside a file; sizes are checked against
// the voxel limits before anything is allocated.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/volume.hpp"

namespace beamcast {

// The voxels a volume may still have: what the scene's limit
// (SceneLimits::max_volume_voxels) leaves after its earlier volumes.
struct VoxelBudget {
  std::int64_t left = 0;
  std::int64_t limit = 0;
};

enum class VolumeSampleType : std::uint8_t { kU8, kI8, kU16, kI16, kU32, kI32, kF32, kF64 };
std::size_t sample_size(VolumeSampleType t);
std::string_view sample_type_name(VolumeSampleType t);  // "uint8", ..., "float32", "float64"
bool is_float(VolumeSampleType t);

// A file's voxels as stored, before normalization: x fastest, then y, z.
struct VolumeFileData {
  std::array<int, 3> dims{0, 0, 0};
  VolumeSampleType type = VolumeSampleType::kU8;
  bool big_endian = false;
  std::vector<unsigned char> bytes;  // dims' product x sample_size(type)
  std::optional<Vec3> spacing;       // from the header (NRRD spacings, INR VX VY VZ, ...)
};

// A volume file named by a scene: where it is, its name as the scene gives
// it (for messages), the JSON pointer of the "file" field (for errors) and
// the assets directory it was resolved in (for files a header names).
struct VolumeFileRef {
  std::filesystem::path full;
  std::string name;
  std::string json_path;
  std::filesystem::path assets_dir;
};

// Dimensions read from a scene or a header, checked in this order: each at
// least 2 ("out_of_range" at axis_paths[a]); their product, computed with an
// overflow guard, at most `budget` voxels ("limit_exceeded" at `path`,
// max_volume_voxels, the room the scene's other volumes leave); each at most
// kMaxVolumeDimension ("out_of_range"). `what` names them in messages
// ("dimensions", "\"ct.nrrd\"'s sizes").
std::array<int, 3> check_volume_dims(const std::array<std::int64_t, 3>& dims, const VoxelBudget& budget,
                                     const std::string& what,
                                     const std::array<std::string, 3>& axis_paths,
                                     const std::string& path);

// A headerless file of exactly the voxels `dims` and `type` give (shorter or
// longer: "bad_volume", with the byte counts expected and found).
VolumeFileData read_raw_volume(const VolumeFileRef& f, const std::array<int, 3>& dims,
                               VolumeSampleType type, bool big_endian);
// The smallest and largest sample; "bad_volume" naming the voxel (index and
// x, y, z) if a float sample is NaN or infinite.
std::array<double, 2> volume_data_range(const VolumeFileData& d, const VolumeFileRef& f);
// Each sample v as round(clamp((v - lo) / (hi - lo), 0, 1) x 65535).
std::shared_ptr<const VolumeGrid> normalize_volume(const VolumeFileData& d,
                                                   const std::array<double, 2>& range);

}  // namespace beamcast
