// NRRD volume files: a row of the volume-format table (volume_formats.cpp).
#pragma once

#include <string_view>

#include "protocol/volume_files.hpp"

namespace beamcast {

// The signature: "NRRD0001" to "NRRD0005".
bool is_nrrd(std::string_view head);
// An NRRD file with an attached header: dimension 3; types uint8, int8,
// uint16, int16, float, double (and their NRRD aliases); encoding raw or
// gzip; "spacings" (or the lengths of "space directions") as its spacing.
VolumeFileData read_nrrd_volume(const VolumeFileRef& f, const VoxelBudget& budget);

}  // namespace beamcast
