// The volume-file formats with a header (docs/scene-format.md, "Volumes"):
// one row each, naming the format, its file-name extensions, its signature
// test and its reader. A new format is its own file in this folder plus one
// row in volume_formats.cpp (docs/architecture.md, "Volume formats").
#pragma once

#include <array>
#include <span>
#include <string_view>

#include "protocol/volume.hpp"
#include "protocol/volume_files.hpp"

namespace beamcast {

struct VolumeFormat {
  std::string_view name;    // the source's "type" ("nrrd")
  VolumeSourceType source;  // Volume::source for files of this format
  // Lower-case name endings, with the dot (".nrrd"; unused entries empty).
  std::array<std::string_view, 3> extensions;
  // Whether a file's first bytes (gunzipped when the file is gzip) carry
  // the format's signature.
  bool (*signature)(std::string_view head);
  // The voxels, or a ProtocolError at the file's JSON path.
  VolumeFileData (*read)(const VolumeFileRef& f, const VoxelBudget& budget);
};

// Every row, in the order hello lists them.
std::span<const VolumeFormat> volume_formats();

// The format of a file whose source gives no "type": the first row whose
// signature its first bytes carry, else the row whose extension its name
// ends in (case aside); neither is "bad_volume" at the file's JSON path.
const VolumeFormat& detect_volume_format(const VolumeFileRef& f);

// A file read as the row `format` says (the source's "type"): refused
// ("bad_volume") when its first bytes carry another row's signature.
VolumeFileData read_volume_file(const VolumeFormat& format, const VolumeFileRef& f,
                                const VoxelBudget& budget);

}  // namespace beamcast
