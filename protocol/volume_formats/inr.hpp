// INRIA image volume files: a row of the volume-format table
// (volume_formats.cpp).
#pragma once

#include <string_view>

#include "protocol/volume_files.hpp"

namespace beamcast {

// The signature: "#INRIMAGE-4#{" (of the gunzipped bytes for .inr.gz).
bool is_inr(std::string_view head);
// An INRIA image: the "#INRIMAGE-4#{" header of 256-byte blocks ending
// "##}", VDIM=1, TYPE unsigned fixed, signed fixed or float, PIXSIZE 8 to
// 64 bits, CPU decm/alpha/pc (little-endian) or sun/sgi (big-endian),
// VX/VY/VZ as its spacing. Read through gzip when it starts as gzip does
// (.inr.gz).
VolumeFileData read_inr_volume(const VolumeFileRef& f, const VoxelBudget& budget);

}  // namespace beamcast
