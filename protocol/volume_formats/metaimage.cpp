// MetaImage volumes (docs/scene-format.md, "Volumes"): a row of the
// volume-format table (volume_formats.cpp).
#include "protocol/volume_formats/metaimage.hpp"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <optional>

#include "protocol/asset_files.hpp"
#include "protocol/errors.hpp"
#include "protocol/volume_formats/format_support.hpp"

namespace beamcast {

using namespace volume_io;

namespace {

// Real headers are a dozen lines of a few dozen bytes; these bound what a
// bad file costs.
constexpr std::size_t kMaxHeader = 1 << 16;
constexpr std::size_t kMaxLine = 1024;
constexpr std::size_t kMaxLines = 128;

// A zlib (or gzip) stream from an offset of a file, inflated as it is read.
class ZlibReader : public ByteStream {
 public:
  ZlibReader(const VolumeFileRef& f, std::uint64_t offset) : f_(f), in_(f.full, std::ios::binary) {
    if (!in_ || !in_.seekg(static_cast<std::streamoff>(offset))) bad(f_, "could not be opened");
    // 15 + 32: a window of up to 32 KiB, zlib or gzip header detected.
    if (inflateInit2(&z_, 15 + 32) != Z_OK) bad(f_, "could not start zlib");
  }
  ZlibReader(const ZlibReader&) = delete;
  ZlibReader& operator=(const ZlibReader&) = delete;
  ~ZlibReader() override { inflateEnd(&z_); }

  std::size_t read(unsigned char* out, std::size_t n) override {
    std::size_t got = 0;
    while (got < n && !ended_) {
      if (z_.avail_in == 0) {
        in_.read(reinterpret_cast<char*>(buffer_.data()), static_cast<std::streamsize>(buffer_.size()));
        z_.next_in = buffer_.data();
        z_.avail_in = static_cast<uInt>(in_.gcount());
        if (z_.avail_in == 0) break;  // the file ends inside the stream: fewer bytes
      }
      const std::size_t chunk = std::min<std::size_t>(n - got, 1u << 24);
      z_.next_out = out + got;
      z_.avail_out = static_cast<uInt>(chunk);
      const int r = inflate(&z_, Z_NO_FLUSH);
      if (r != Z_OK && r != Z_STREAM_END && r != Z_BUF_ERROR) {
        bad(f_, std::string("holds corrupt zlib data: ") + (z_.msg ? z_.msg : "inflate failed"));
      }
      got += chunk - z_.avail_out;
      ended_ = r == Z_STREAM_END;
    }
    return got;
  }

 private:
  const VolumeFileRef& f_;
  std::ifstream in_;
  z_stream z_{};
  std::array<unsigned char, 1 << 16> buffer_{};
  bool ended_ = false;
};

// "True" or "False" (MetaIO also writes "true", "false", "1", "0").
bool boolean(const VolumeFileRef& f, const std::string& key, const std::string& value) {
  if (value == "True" || value == "true" || value == "1") return true;
  if (value == "False" || value == "false" || value == "0") return false;
  bad(f, "has " + key + " = " + value.substr(0, 40) + "; it is True or False");
}

std::array<std::string, 3> three(const VolumeFileRef& f, const std::string& key,
                                 const std::string& value) {
  const auto w = words(value);
  if (w.size() != 3) {
    bad(f, "has " + key + " = " + value.substr(0, 60) + "; a volume has 3 (NDims = 3)");
  }
  return {w[0], w[1], w[2]};
}

std::optional<VolumeSampleType> element_type(const std::string& name) {
  static const std::pair<std::string_view, VolumeSampleType> kTypes[] = {
      {"MET_UCHAR", VolumeSampleType::kU8},  {"MET_CHAR", VolumeSampleType::kI8},
      {"MET_USHORT", VolumeSampleType::kU16}, {"MET_SHORT", VolumeSampleType::kI16},
      {"MET_UINT", VolumeSampleType::kU32},   {"MET_INT", VolumeSampleType::kI32},
      {"MET_FLOAT", VolumeSampleType::kF32},  {"MET_DOUBLE", VolumeSampleType::kF64}};
  for (const auto& [n, t] : kTypes) {
    if (name == n) return t;
  }
  return std::nullopt;
}

// The fields read from a header, and where its data starts.
struct Header {
  std::optional<std::int64_t> ndims;
  std::optional<std::array<std::int64_t, 3>> dims;
  std::optional<VolumeSampleType> type;
  std::optional<Vec3> spacing;
  bool big_endian = false, compressed = false;
  std::string data_file;  // "LOCAL" or a file name
  std::uint64_t data_offset = 0;
};

void read_field(const VolumeFileRef& f, const std::string& key, const std::string& value,
                Header* h) {
  if (key == "ObjectType") {
    if (value != "Image") bad(f, "has ObjectType = " + value.substr(0, 40) + "; a volume is Image");
  } else if (key == "NDims") {
    h->ndims = parse_int(value);
    if (h->ndims != 3) bad(f, "has NDims = " + value.substr(0, 40) + "; a volume has 3");
  } else if (key == "DimSize") {
    std::array<std::int64_t, 3> d{};
    const auto w = three(f, key, value);
    for (int a = 0; a < 3; ++a) {
      const auto v = parse_int(w[a]);
      if (!v) bad(f, "has DimSize = " + value.substr(0, 60) + ", not integers");
      d[a] = *v;
    }
    h->dims = d;
  } else if (key == "ElementType") {
    h->type = element_type(value);
    if (!h->type) {
      bad(f, "has ElementType " + value.substr(0, 40) +
                 "; supported: MET_UCHAR, MET_CHAR, MET_USHORT, MET_SHORT, MET_UINT, MET_INT, "
                 "MET_FLOAT, MET_DOUBLE");
    }
  } else if (key == "ElementSpacing") {
    const auto w = three(f, key, value);
    h->spacing = Vec3{header_spacing(f, key, w[0]), header_spacing(f, key, w[1]),
                      header_spacing(f, key, w[2])};
  } else if (key == "ElementNumberOfChannels") {
    if (value != "1") {
      bad(f, "has ElementNumberOfChannels = " + value.substr(0, 40) +
                 "; a scalar volume has one value per voxel");
    }
  } else if (key == "BinaryData") {
    if (!boolean(f, key, value)) bad(f, "has BinaryData = False; only binary data is read");
  } else if (key == "BinaryDataByteOrderMSB" || key == "ElementByteOrderMSB") {
    h->big_endian = boolean(f, key, value);
  } else if (key == "CompressedData") {
    h->compressed = boolean(f, key, value);
  } else if (key == "HeaderSize") {
    if (value != "0") bad(f, "has HeaderSize = " + value.substr(0, 40) + "; skipping is not supported");
  }
  // Other fields (Offset, TransformMatrix, AnatomicalOrientation,
  // CompressedDataSize, Comment, ...) do not change how the voxels are read.
}

// The header's lines up to ElementDataFile, which ends it.
Header read_header(const VolumeFileRef& f) {
  const std::string text = read_prefix(f, kMaxHeader);
  Header h;
  std::size_t at = 0;
  for (std::size_t n = 1;; ++n) {
    if (n > kMaxLines) {
      bad(f, "has no ElementDataFile line ending its header in its first " +
                 std::to_string(kMaxLines) + " lines");
    }
    std::size_t end = text.find('\n', at);
    const std::size_t stop = end == std::string::npos ? text.size() : end;
    if (stop - at > kMaxLine) {
      bad(f, "has a header line longer than " + std::to_string(kMaxLine) + " bytes (line " +
                 std::to_string(n) + ")");
    }
    if (end == std::string::npos) {
      bad(f, "ends without an ElementDataFile line ending its header");
    }
    const std::string line = trim(std::string_view(text).substr(at, stop - at));
    at = end + 1;
    if (line.empty()) continue;
    const auto eq = line.find('=');
    if (eq == std::string::npos) {
      bad(f, "has a header line that is not \"Key = Value\" (line " + std::to_string(n) + ": \"" +
                 line.substr(0, 60) + "\")");
    }
    const std::string key = trim(std::string_view(line).substr(0, eq));
    const std::string value = trim(std::string_view(line).substr(eq + 1));
    if (key == "ElementDataFile") {
      h.data_file = value;
      h.data_offset = at;
      return h;
    }
    read_field(f, key, value, &h);
  }
}

// The .mhd's data file: named relative to the header's folder, under the
// scene's rules for paths (no "..", nothing absolute, inside the assets).
VolumeFileRef data_file_ref(const VolumeFileRef& f, const std::string& name) {
  if (name == "LIST" || name.find('%') != std::string::npos || words(name).size() != 1) {
    bad(f, "names its data as a list or pattern of files (\"" + name.substr(0, 60) +
               "\"); one data file or LOCAL is read");
  }
  const std::string rel = (std::filesystem::path(f.name).parent_path() / name).string();
  try {
    return {resolve_asset_path(f.assets_dir, rel, f.json_path, "volume"), rel, f.json_path,
            f.assets_dir};
  } catch (const ProtocolError& e) {
    ErrorInfo info = e.info();
    info.message = "volume file " + quoted(f.name) + "'s ElementDataFile: " + info.message;
    throw ProtocolError(std::move(info));
  }
}

}  // namespace

bool is_metaimage(std::string_view head) {
  const auto b = head.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos) return false;
  const auto e = head.find_first_of(" \t=", b);
  if (e == std::string_view::npos) return false;
  const std::string_view key = head.substr(b, e - b);
  const auto eq = head.find_first_not_of(" \t", e);
  return eq != std::string_view::npos && head[eq] == '=' &&
         (key == "ObjectType" || key == "NDims" || key == "Comment" || key == "ObjectSubType");
}

VolumeFileData read_metaimage_volume(const VolumeFileRef& f, const VoxelBudget& budget) {
  const Header h = read_header(f);
  if (!h.ndims) bad(f, "has no NDims field");
  if (!h.dims) bad(f, "has no DimSize field");
  if (!h.type) bad(f, "has no ElementType field");
  VolumeFileData d;
  d.dims = header_dims(f, *h.dims, budget, "DimSize");
  d.type = *h.type;
  d.big_endian = h.big_endian;
  d.spacing = h.spacing;
  const bool local = h.data_file == "LOCAL";
  const VolumeFileRef data = local ? f : data_file_ref(f, h.data_file);
  const std::uint64_t offset = local ? h.data_offset : 0;
  if (!h.compressed) {
    d.bytes = read_plain_payload(data, offset, d.dims, d.type);
  } else {
    ZlibReader in(data, offset);
    d.bytes = read_stream_payload(in, data, d.dims, d.type, "zlib");
  }
  return d;
}

}  // namespace beamcast
