#include "protocol/volume_formats/volume_formats.hpp"

#include <algorithm>
#include <cctype>
#include <string>

#include "protocol/volume_formats/format_support.hpp"
#include "protocol/volume_formats/inr.hpp"
#include "protocol/volume_formats/metaimage.hpp"
#include "protocol/volume_formats/nrrd.hpp"

namespace beamcast {

namespace {

// One row per format: a new format is its own file and one row here.
const VolumeFormat kFormats[] = {
    {"nrrd", VolumeSourceType::kNrrd, {".nrrd"}, is_nrrd, read_nrrd_volume},
    {"inr", VolumeSourceType::kInr, {".inr", ".inr.gz"}, is_inr, read_inr_volume},
    {"metaimage", VolumeSourceType::kFile, {".mha", ".mhd"}, is_metaimage, read_metaimage_volume},
};

// Enough for every row's signature.
constexpr std::size_t kHeadBytes = 256;

const VolumeFormat* by_signature(std::string_view head) {
  for (const VolumeFormat& row : kFormats) {
    if (row.signature(head)) return &row;
  }
  return nullptr;
}

const VolumeFormat* by_extension(const std::string& name) {
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const VolumeFormat& row : kFormats) {
    for (std::string_view ext : row.extensions) {
      if (!ext.empty() && volume_io::ends_with(lower, ext)) return &row;
    }
  }
  return nullptr;
}

}  // namespace

std::span<const VolumeFormat> volume_formats() { return kFormats; }

const VolumeFormat& detect_volume_format(const VolumeFileRef& f) {
  if (const VolumeFormat* row = by_signature(volume_io::file_head(f, kHeadBytes))) return *row;
  if (const VolumeFormat* row = by_extension(f.name)) return *row;
  std::string names, extensions;
  for (const VolumeFormat& row : kFormats) {
    names += (names.empty() ? "" : ", ") + std::string(row.name);
    for (std::string_view ext : row.extensions) {
      if (!ext.empty()) extensions += (extensions.empty() ? "" : ", ") + std::string(ext);
    }
  }
  volume_io::bad(f, "is in no format read here: its first bytes carry no known signature and "
                    "its name ends in none of " + extensions +
                    " (formats: " + names + "; a headerless file is \"type\": \"raw\")");
}

VolumeFileData read_volume_file(const VolumeFormat& format, const VolumeFileRef& f,
                                const VoxelBudget& budget) {
  const VolumeFormat* seen = by_signature(volume_io::file_head(f, kHeadBytes));
  if (seen && seen != &format) {
    volume_io::bad(f, "is " + std::string(seen->name) + " (its first bytes say so), not " +
                          std::string(format.name) +
                          " as the source's \"type\" says; leave \"type\" out to read it as "
                          "the file says");
  }
  return format.read(f, budget);
}

}  // namespace beamcast
