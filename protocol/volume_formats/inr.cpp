// INRIA .inr volumes (docs/scene-format.md, "Volumes"): a row of the
// volume-format table (volume_formats.cpp).
#include "protocol/volume_formats/inr.hpp"

#include <fstream>
#include <memory>

#include "protocol/volume_formats/format_support.hpp"

namespace beamcast {

using namespace volume_io;

bool is_inr(std::string_view head) { return head.starts_with("#INRIMAGE-4#{"); }

VolumeFileData read_inr_volume(const VolumeFileRef& f, const VoxelBudget& budget) {
  // Gzip-compressed (.inr.gz) by its first bytes, whatever its name.
  const bool gz = read_prefix(f, 2) == "\x1f\x8b";
  // Header blocks of 256 bytes until one holds "##}"; real headers take
  // one block, 64 bound what a bad file costs.
  constexpr std::size_t kBlock = 256, kMaxBlocks = 64;
  std::unique_ptr<GzReader> gzr;
  std::ifstream plain;
  if (gz) {
    gzr = std::make_unique<GzReader>(gzopen(f.full.c_str(), "rb"), f);
  } else {
    plain.open(f.full, std::ios::binary);
    if (!plain) bad(f, "could not be opened");
  }
  std::string head;
  std::size_t end = std::string::npos;
  while (end == std::string::npos) {
    if (head.size() >= kBlock * kMaxBlocks) {
      bad(f, "has no \"##}\" ending its header in its first " +
                 std::to_string(kBlock * kMaxBlocks) + " bytes");
    }
    const std::size_t at = head.size();
    head.resize(at + kBlock);
    std::size_t got = 0;
    if (gzr) {
      got = gzr->read(reinterpret_cast<unsigned char*>(head.data() + at), kBlock);
    } else {
      plain.read(head.data() + at, kBlock);
      got = static_cast<std::size_t>(plain.gcount());
    }
    if (at == 0 && head.compare(0, 13, "#INRIMAGE-4#{") != 0) {
      bad(f, "is not an INRIA image (it does not start with \"#INRIMAGE-4#{\")");
    }
    if (got < kBlock) bad(f, "ends inside its header (headers are blocks of 256 bytes)");
    end = head.find("\n##}");
  }
  const std::uint64_t offset = head.size();

  std::optional<std::int64_t> xdim, ydim, zdim;
  std::int64_t vdim = 1;
  std::string type_name, pixsize, cpu = "decm";
  Vec3 spacing{1.0, 1.0, 1.0};
  bool has_spacing = false;
  const std::vector<std::string> ls = lines(std::string_view(head).substr(0, end + 1));
  for (std::size_t n = 1; n < ls.size(); ++n) {
    const std::string& line = ls[n];
    if (line.empty() || line[0] == '#') continue;
    const auto eq = line.find('=');
    if (eq == std::string::npos) {
      bad(f, "has a header line that is not KEY=VALUE (line " + std::to_string(n + 1) + ": \"" +
                 line.substr(0, 60) + "\")");
    }
    const std::string key = trim(std::string_view(line).substr(0, eq));
    const std::string value = trim(std::string_view(line).substr(eq + 1));
    auto integer = [&] {
      const auto v = parse_int(value);
      if (!v) bad(f, "has " + key + "=" + value.substr(0, 40) + ", not an integer");
      return *v;
    };
    if (key == "XDIM") {
      xdim = integer();
    } else if (key == "YDIM") {
      ydim = integer();
    } else if (key == "ZDIM") {
      zdim = integer();
    } else if (key == "VDIM") {
      vdim = integer();
    } else if (key == "TYPE") {
      type_name = value;
    } else if (key == "PIXSIZE") {
      pixsize = value;
    } else if (key == "CPU") {
      cpu = value;
    } else if (key == "VX" || key == "VY" || key == "VZ") {
      spacing[static_cast<std::size_t>(key[1] - 'X')] = header_spacing(f, key, value);
      has_spacing = true;
    }
    // SCALE (fixed-point scaling: the range maps the values anyway), the
    // origin (XO, YO, ZO; TX, TY, TZ) and the rest do not change the voxels.
  }
  if (!xdim || !ydim || !zdim) bad(f, "lacks XDIM, YDIM or ZDIM in its header");
  if (vdim != 1) {
    bad(f, "has VDIM=" + std::to_string(vdim) + "; a scalar volume has one value per voxel");
  }
  const auto bits_end = pixsize.find(" bits");
  const auto bits = parse_int(pixsize.substr(0, bits_end));
  if (pixsize.empty() || bits_end == std::string::npos || !bits) {
    bad(f, "has PIXSIZE \"" + pixsize.substr(0, 40) + "\"; it is \"8 bits\" to \"64 bits\"");
  }
  std::optional<VolumeSampleType> type;
  if (type_name == "unsigned fixed") {
    type = *bits == 8    ? VolumeSampleType::kU8
           : *bits == 16 ? VolumeSampleType::kU16
           : *bits == 32 ? std::optional(VolumeSampleType::kU32)
                         : std::nullopt;
  } else if (type_name == "signed fixed") {
    type = *bits == 8    ? VolumeSampleType::kI8
           : *bits == 16 ? VolumeSampleType::kI16
           : *bits == 32 ? std::optional(VolumeSampleType::kI32)
                         : std::nullopt;
  } else if (type_name == "float") {
    type = *bits == 32   ? VolumeSampleType::kF32
           : *bits == 64 ? std::optional(VolumeSampleType::kF64)
                         : std::nullopt;
  } else {
    bad(f, "has TYPE \"" + type_name.substr(0, 40) +
               "\"; supported: unsigned fixed, signed fixed, float");
  }
  if (!type) bad(f, "has TYPE=" + type_name + " with PIXSIZE=" + pixsize + ", not supported");
  bool big = false;
  if (cpu == "sun" || cpu == "sgi") {
    big = true;
  } else if (cpu != "decm" && cpu != "alpha" && cpu != "pc") {
    bad(f, "has CPU=" + cpu.substr(0, 40) + "; it is decm, alpha, pc (little-endian), sun or sgi");
  }
  VolumeFileData d;
  d.dims = header_dims(f, {*xdim, *ydim, *zdim}, budget, "XDIM, YDIM, ZDIM");
  d.type = *type;
  d.big_endian = big;
  if (has_spacing) d.spacing = spacing;
  d.bytes = gzr ? read_stream_payload(*gzr, f, d.dims, d.type, "gzip")
                : read_plain_payload(f, offset, d.dims, d.type);
  return d;
}

}  // namespace beamcast
