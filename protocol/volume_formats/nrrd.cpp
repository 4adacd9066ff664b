// NRRD volumes (docs/scene-format.md, "Volumes"): a row of the volume-format
// table (volume_formats.cpp).
#include "protocol/volume_formats/nrrd.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>

#include "protocol/volume_formats/format_support.hpp"

namespace beamcast {

using namespace volume_io;

namespace {

// The lengths of NRRD "space directions" vectors "(a,b,c) (d,e,f) (g,h,i)".
std::optional<Vec3> direction_lengths(const VolumeFileRef& f, const std::string& value) {
  Vec3 out{};
  std::size_t at = 0;
  for (int a = 0; a < 3; ++a) {
    const auto open = value.find('(', at);
    const auto close = value.find(')', open == std::string::npos ? at : open);
    if (open == std::string::npos || close == std::string::npos) {
      // "none" for an axis without a direction (not a spatial axis): no spacing known.
      if (value.find("none", at) != std::string::npos) return std::nullopt;
      bad(f, "has a bad \"space directions\" field: \"" + value + "\"");
    }
    std::string inner = value.substr(open + 1, close - open - 1);
    std::replace(inner.begin(), inner.end(), ',', ' ');
    double sum = 0.0;
    const auto parts = words(inner);
    for (const std::string& w : parts) {
      const auto v = parse_double(w);
      if (!v || !std::isfinite(*v))
        bad(f, "has a bad \"space directions\" field: \"" + value + "\"");
      sum += *v * *v;
    }
    if (parts.empty() || !(sum > 0.0)) {
      bad(f, "has a zero or empty vector in \"space directions\": \"" + value + "\"");
    }
    out[a] = std::sqrt(sum);
    at = close + 1;
  }
  return out;
}

}  // namespace

bool is_nrrd(std::string_view head) {
  return head.size() >= 8 && head.compare(0, 7, "NRRD000") == 0 && head[7] >= '1' &&
         head[7] <= '5';
}

VolumeFileData read_nrrd_volume(const VolumeFileRef& f, const VoxelBudget& budget) {
  // The header ends at the first empty line; 64 KiB is far more than any
  // real header (a few hundred bytes) and bounds what a bad file costs.
  constexpr std::size_t kMaxHeader = 1 << 16;
  const std::string head = read_prefix(f, kMaxHeader);
  if (!is_nrrd(head)) {
    bad(f, "is not an NRRD file (it does not start with NRRD0001 to NRRD0005)");
  }
  std::size_t end = head.find("\n\n"), skip = 2;
  if (const auto crlf = head.find("\r\n\r\n"); crlf != std::string::npos && crlf < end) {
    end = crlf;
    skip = 4;
  }
  if (end == std::string::npos) {
    bad(f, "has no empty line ending its header in its first " + std::to_string(kMaxHeader) +
               " bytes (NRRD with an attached header: the data follows an empty line)");
  }
  const std::uint64_t offset = end + skip;

  std::optional<VolumeSampleType> type;
  std::optional<std::int64_t> dimension;
  std::optional<std::array<std::int64_t, 3>> sizes;
  std::optional<Vec3> spacings, directions;
  std::string encoding, endian;
  const std::vector<std::string> ls = lines(std::string_view(head).substr(0, end));
  for (std::size_t n = 1; n < ls.size(); ++n) {
    const std::string& line = ls[n];
    if (line.empty() || line[0] == '#') continue;
    const auto colon = line.find(": ");
    const auto kv = line.find(":=");
    if (kv != std::string::npos && (colon == std::string::npos || kv < colon)) continue;
    if (colon == std::string::npos) {
      bad(f, "has a header line that is not \"field: value\" (line " + std::to_string(n + 1) +
                 ": \"" + line.substr(0, 60) + "\")");
    }
    const std::string key = line.substr(0, colon);
    const std::string value = trim(std::string_view(line).substr(colon + 2));
    if (key == "type") {
      static const std::pair<std::string_view, VolumeSampleType> kTypes[] = {
          {"uchar", VolumeSampleType::kU8},
          {"unsigned char", VolumeSampleType::kU8},
          {"uint8", VolumeSampleType::kU8},
          {"uint8_t", VolumeSampleType::kU8},
          {"signed char", VolumeSampleType::kI8},
          {"int8", VolumeSampleType::kI8},
          {"int8_t", VolumeSampleType::kI8},
          {"short", VolumeSampleType::kI16},
          {"short int", VolumeSampleType::kI16},
          {"signed short", VolumeSampleType::kI16},
          {"signed short int", VolumeSampleType::kI16},
          {"int16", VolumeSampleType::kI16},
          {"int16_t", VolumeSampleType::kI16},
          {"ushort", VolumeSampleType::kU16},
          {"unsigned short", VolumeSampleType::kU16},
          {"unsigned short int", VolumeSampleType::kU16},
          {"uint16", VolumeSampleType::kU16},
          {"uint16_t", VolumeSampleType::kU16},
          {"float", VolumeSampleType::kF32},
          {"double", VolumeSampleType::kF64}};
      for (const auto& [name, t] : kTypes) {
        if (value == name) type = t;
      }
      if (!type) {
        bad(f, "has type \"" + value.substr(0, 40) +
                   "\"; supported: uint8, int8, uint16, int16, float, double");
      }
    } else if (key == "dimension") {
      dimension = parse_int(value);
      if (dimension != 3) bad(f, "has dimension \"" + value + "\"; a volume is 3-dimensional");
    } else if (key == "sizes") {
      const auto w = words(value);
      std::array<std::int64_t, 3> s{};
      for (std::size_t a = 0; a < w.size() && a < 3; ++a) {
        const auto v = parse_int(w[a]);
        if (!v) bad(f, "has sizes \"" + value.substr(0, 60) + "\" that are not integers");
        s[a] = *v;
      }
      if (w.size() != 3) bad(f, "has sizes \"" + value.substr(0, 60) + "\"; a volume has 3");
      sizes = s;
    } else if (key == "spacings") {
      const auto w = words(value);
      if (w.size() != 3) bad(f, "has spacings \"" + value.substr(0, 60) + "\"; a volume has 3");
      spacings = Vec3{header_spacing(f, "spacing", w[0]), header_spacing(f, "spacing", w[1]),
                      header_spacing(f, "spacing", w[2])};
    } else if (key == "space directions") {
      directions = direction_lengths(f, value);
    } else if (key == "encoding") {
      encoding = value;
    } else if (key == "endian") {
      endian = value;
    } else if (key == "data file" || key == "datafile") {
      bad(f, "names a separate data file; only NRRD files with the data attached are read");
    } else if (key == "line skip" || key == "lineskip" || key == "byte skip" || key == "byteskip") {
      if (value != "0") bad(f, "has \"" + key + ": " + value + "\"; skipping is not supported");
    }
    // Other fields (content, kinds, centers, space, space origin, ...) do
    // not change how the voxels are read.
  }
  if (!type) bad(f, "has no \"type\" field");
  if (!dimension) bad(f, "has no \"dimension\" field");
  if (!sizes) bad(f, "has no \"sizes\" field");
  const bool gzip = encoding == "gzip" || encoding == "gz";
  if (encoding.empty()) bad(f, "has no \"encoding\" field");
  if (!gzip && encoding != "raw") {
    bad(f, "has encoding \"" + encoding.substr(0, 40) + "\"; supported: raw, gzip");
  }
  if (sample_size(*type) > 1 && endian != "little" && endian != "big") {
    bad(f, endian.empty() ? "has no \"endian\" field, needed for " +
                                std::string(sample_type_name(*type)) + " data"
                          : "has endian \"" + endian.substr(0, 40) + "\"; it is little or big");
  }
  VolumeFileData d;
  d.dims = header_dims(f, *sizes, budget, "sizes");
  d.type = *type;
  d.big_endian = endian == "big";
  d.spacing = spacings ? spacings : directions;
  if (!gzip) {
    d.bytes = read_plain_payload(f, offset, d.dims, d.type);
    return d;
  }
  // The gzip stream starts after the header: zlib reads a descriptor from
  // its current position.
  const int fd = ::open(f.full.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) bad(f, "could not be opened");
  if (::lseek(fd, static_cast<off_t>(offset), SEEK_SET) < 0) {
    ::close(fd);
    bad(f, "could not be read past its header");
  }
  gzFile gz = gzdopen(fd, "rb");
  if (!gz) ::close(fd);
  GzReader reader(gz, f);
  if (reader.direct()) bad(f, "says encoding gzip, but its data is not gzip-compressed");
  d.bytes = read_stream_payload(reader, f, d.dims, d.type, "gzip");
  return d;
}

}  // namespace beamcast
