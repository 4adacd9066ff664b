// MetaImage volume files (ITK's MetaIO: .mha, .mhd + raw data): a row of the
// volume-format table (volume_formats.cpp).
#pragma once

#include <string_view>

#include "protocol/volume_files.hpp"

namespace beamcast {

// The signature: a first "Key = Value" line whose key is one MetaIO writes
// first (ObjectType, NDims, Comment, ObjectSubType).
bool is_metaimage(std::string_view head);
// A MetaImage: "Key = Value" header lines ending with ElementDataFile; NDims
// 3, DimSize, ElementType MET_UCHAR, MET_CHAR, MET_USHORT, MET_SHORT,
// MET_UINT, MET_INT, MET_FLOAT or MET_DOUBLE, ElementSpacing as its spacing,
// ElementByteOrderMSB (or BinaryDataByteOrderMSB), CompressedData (zlib).
// ElementDataFile LOCAL: the data follows the header (.mha); else the name
// of the data file, relative to the header's folder and confined to the
// assets directory like the scene's own paths (.mhd).
VolumeFileData read_metaimage_volume(const VolumeFileRef& f, const VoxelBudget& budget);

}  // namespace beamcast
