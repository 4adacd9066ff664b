#include "protocol/volume_files.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <system_error>

#include "protocol/json_reader.hpp"

namespace beamcast {

using json_read::fail;

namespace {

std::string dims_text(const std::array<std::int64_t, 3>& d) {
  return "[" + std::to_string(d[0]) + ", " + std::to_string(d[1]) + ", " + std::to_string(d[2]) +
         "]";
}

std::string quoted(const std::string& name) { return "\"" + name + "\""; }

[[noreturn]] void bad(const VolumeFileRef& f, const std::string& why) {
  fail("bad_volume", f.json_path, "volume file " + quoted(f.name) + " " + why);
}

// "its dimensions [64, 64, 64] of float32 (4 bytes each)", for size messages.
std::string layout_text(const std::array<int, 3>& dims, VolumeSampleType t) {
  return "its dimensions " + dims_text({dims[0], dims[1], dims[2]}) + " of " +
         std::string(sample_type_name(t)) + " (" + std::to_string(sample_size(t)) +
         (sample_size(t) == 1 ? " byte" : " bytes") + " each)";
}

std::uint64_t payload_bytes(const std::array<int, 3>& dims, VolumeSampleType t) {
  return static_cast<std::uint64_t>(dims[0]) * dims[1] * dims[2] * sample_size(t);
}

// Exactly `expected` bytes from offset `offset` of a plain file: its size is
// checked first, so a wrong size allocates nothing.
std::vector<unsigned char> read_plain_payload(const VolumeFileRef& f, std::uint64_t offset,
                                              const std::array<int, 3>& dims, VolumeSampleType t) {
  const std::uint64_t expected = payload_bytes(dims, t);
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(f.full, ec);
  if (ec) bad(f, "could not be read: " + ec.message());
  const std::uint64_t found = size > offset ? size - offset : 0;
  const std::string where =
      offset > 0 ? " after its " + std::to_string(offset) + "-byte header" : "";
  if (found < expected) {
    bad(f, "is too short: " + layout_text(dims, t) + " need " + std::to_string(expected) +
               " bytes of voxel data" + where + ", found " + std::to_string(found));
  }
  if (found > expected) {
    bad(f, "is longer than its header or the scene says: " + layout_text(dims, t) + " need " +
               std::to_string(expected) + " bytes of voxel data" + where + ", found " +
               std::to_string(found));
  }
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(f.full.c_str(), "rb"),
                                                       &std::fclose);
  if (!file) bad(f, "could not be opened");
  std::vector<unsigned char> bytes(expected);
  if (std::fseek(file.get(), static_cast<long>(offset), SEEK_SET) != 0 ||
      std::fread(bytes.data(), 1, bytes.size(), file.get()) != bytes.size()) {
    bad(f, "could not be read to its end");
  }
  return bytes;
}

// A gzip stream being read, closed on destruction.
class GzReader {
 public:
  GzReader(gzFile gz, const VolumeFileRef& f) : gz_(gz), f_(f) {
    if (!gz_) bad(f_, "could not be opened");
    gzbuffer(gz_, 1 << 17);
  }
  GzReader(const GzReader&) = delete;
  GzReader& operator=(const GzReader&) = delete;
  ~GzReader() { gzclose(gz_); }
  bool direct() { return gzdirect(gz_) != 0; }
  // Up to n bytes; fewer only at the end of the data.
  std::size_t read(unsigned char* out, std::size_t n) {
    std::size_t got = 0;
    while (got < n) {
      const unsigned chunk = static_cast<unsigned>(std::min<std::size_t>(n - got, 1u << 24));
      const int r = gzread(gz_, out + got, chunk);
      if (r < 0) {
        int errnum = 0;
        bad(f_, std::string("holds corrupt gzip data: ") + gzerror(gz_, &errnum));
      }
      if (r == 0) break;
      got += static_cast<std::size_t>(r);
    }
    return got;
  }

 private:
  gzFile gz_;
  const VolumeFileRef& f_;
};

// Exactly the voxel data from a gzip stream, and nothing after it.
std::vector<unsigned char> read_gz_payload(GzReader& gz, const VolumeFileRef& f,
                                           const std::array<int, 3>& dims, VolumeSampleType t) {
  const std::uint64_t expected = payload_bytes(dims, t);
  std::vector<unsigned char> bytes(expected);
  const std::size_t got = gz.read(bytes.data(), bytes.size());
  if (got < expected) {
    bad(f, "is too short: " + layout_text(dims, t) + " need " + std::to_string(expected) +
               " bytes of voxel data, its gzip data holds " + std::to_string(got));
  }
  unsigned char extra;
  if (gz.read(&extra, 1) != 0) {
    bad(f, "is longer than its header says: " + layout_text(dims, t) + " need " +
               std::to_string(expected) + " bytes of voxel data, its gzip data holds more");
  }
  return bytes;
}

bool ends_with(const std::string& s, std::string_view suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return std::string(s.substr(b, e - b + 1));
}

std::vector<std::string> words(std::string_view s) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
    const std::size_t b = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t') ++i;
    if (i > b) out.emplace_back(s.substr(b, i - b));
  }
  return out;
}

std::optional<std::int64_t> parse_int(std::string_view s) {
  std::int64_t v = 0;
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size()) return std::nullopt;
  return v;
}

std::optional<double> parse_double(std::string_view s) {
  double v = 0.0;
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size()) return std::nullopt;
  return v;
}

std::vector<std::string> lines(std::string_view text) {
  std::vector<std::string> out;
  std::size_t b = 0;
  while (b <= text.size()) {
    std::size_t e = text.find('\n', b);
    if (e == std::string_view::npos) e = text.size();
    std::string line(text.substr(b, e - b));
    if (!line.empty() && line.back() == '\r') line.pop_back();
    out.push_back(std::move(line));
    b = e + 1;
  }
  return out;
}

// A header spacing: > 0 and finite; `nan` (NRRD: "no spacing") reads as 1.
double header_spacing(const VolumeFileRef& f, const std::string& field, const std::string& s) {
  const auto v = parse_double(s);
  if (v && std::isnan(*v)) return 1.0;
  if (!v || !(*v > 0.0) || !std::isfinite(*v)) {
    bad(f, "has a bad " + field + " \"" + s + "\" (spacings must be numbers > 0)");
  }
  return *v;
}

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

std::array<int, 3> header_dims(const VolumeFileRef& f, const std::array<std::int64_t, 3>& dims,
                               const VoxelBudget& budget, const std::string& what) {
  return check_volume_dims(dims, budget, quoted(f.name) + "'s " + what,
                           {f.json_path, f.json_path, f.json_path}, f.json_path);
}

// Calls fn(index, value) for every sample, in memory order, swapping bytes
// where the file's order is not the machine's.
template <class T, class F>
void each_as(const VolumeFileData& d, F&& fn) {
  constexpr std::size_t kSize = sizeof(T);
  const bool swap = d.big_endian != (std::endian::native == std::endian::big);
  const std::size_t n = d.bytes.size() / kSize;
  const unsigned char* p = d.bytes.data();
  for (std::size_t i = 0; i < n; ++i, p += kSize) {
    unsigned char b[kSize];
    std::memcpy(b, p, kSize);
    if (swap) std::reverse(b, b + kSize);
    T v;
    std::memcpy(&v, b, kSize);
    fn(i, static_cast<double>(v));
  }
}

template <class F>
void each_sample(const VolumeFileData& d, F&& fn) {
  switch (d.type) {
    case VolumeSampleType::kU8:
      return each_as<std::uint8_t>(d, fn);
    case VolumeSampleType::kI8:
      return each_as<std::int8_t>(d, fn);
    case VolumeSampleType::kU16:
      return each_as<std::uint16_t>(d, fn);
    case VolumeSampleType::kI16:
      return each_as<std::int16_t>(d, fn);
    case VolumeSampleType::kU32:
      return each_as<std::uint32_t>(d, fn);
    case VolumeSampleType::kI32:
      return each_as<std::int32_t>(d, fn);
    case VolumeSampleType::kF32:
      return each_as<float>(d, fn);
    case VolumeSampleType::kF64:
      return each_as<double>(d, fn);
  }
}

}  // namespace

std::size_t sample_size(VolumeSampleType t) {
  switch (t) {
    case VolumeSampleType::kU8:
    case VolumeSampleType::kI8:
      return 1;
    case VolumeSampleType::kU16:
    case VolumeSampleType::kI16:
      return 2;
    case VolumeSampleType::kU32:
    case VolumeSampleType::kI32:
    case VolumeSampleType::kF32:
      return 4;
    case VolumeSampleType::kF64:
      return 8;
  }
  return 1;
}

std::string_view sample_type_name(VolumeSampleType t) {
  switch (t) {
    case VolumeSampleType::kU8:
      return "uint8";
    case VolumeSampleType::kI8:
      return "int8";
    case VolumeSampleType::kU16:
      return "uint16";
    case VolumeSampleType::kI16:
      return "int16";
    case VolumeSampleType::kU32:
      return "uint32";
    case VolumeSampleType::kI32:
      return "int32";
    case VolumeSampleType::kF32:
      return "float32";
    case VolumeSampleType::kF64:
      return "float64";
  }
  return "?";
}

bool is_float(VolumeSampleType t) {
  return t == VolumeSampleType::kF32 || t == VolumeSampleType::kF64;
}

std::array<int, 3> check_volume_dims(const std::array<std::int64_t, 3>& dims, const VoxelBudget& budget,
                                     const std::string& what,
                                     const std::array<std::string, 3>& axis_paths,
                                     const std::string& path) {
  for (int a = 0; a < 3; ++a) {
    if (dims[a] < 2) {
      fail("out_of_range", axis_paths[a],
           what + " " + dims_text(dims) +
               " must be at least 2 on every axis (the box spans voxel centre to centre)");
    }
  }
  std::int64_t product = dims[0];
  const bool overflow = __builtin_mul_overflow(product, dims[1], &product) ||
                        __builtin_mul_overflow(product, dims[2], &product);
  const std::string limit = "max_volume_voxels = " + std::to_string(budget.limit);
  if (overflow) {
    fail("limit_exceeded", path,
         what + " " + dims_text(dims) +
             " make more voxels than a 64-bit integer holds, far over the limit " + limit);
  }
  if (product > budget.left) {
    const std::int64_t used = budget.limit - budget.left;
    fail(
        "limit_exceeded", path,
        what + " " + dims_text(dims) + " make " + std::to_string(product) + " voxels" +
            (used > 0 ? " (and the scene's other volumes have " + std::to_string(used) + ")" : "") +
            ", over the limit " + limit + " per scene");
  }
  std::array<int, 3> out{};
  for (int a = 0; a < 3; ++a) {
    if (dims[a] > kMaxVolumeDimension) {
      fail("out_of_range", axis_paths[a],
           what + " " + dims_text(dims) + " exceed " + std::to_string(kMaxVolumeDimension) +
               " voxels on an axis (limit max_volume_dimension)");
    }
    out[a] = static_cast<int>(dims[a]);
  }
  return out;
}

VolumeFileData read_raw_volume(const VolumeFileRef& f, const std::array<int, 3>& dims,
                               VolumeSampleType type, bool big_endian) {
  VolumeFileData d;
  d.dims = dims;
  d.type = type;
  d.big_endian = big_endian;
  d.bytes = read_plain_payload(f, 0, dims, type);
  return d;
}

VolumeFileData read_nrrd_volume(const VolumeFileRef& f, const VoxelBudget& budget) {
  // The header ends at the first empty line; 64 KiB is far more than any
  // real header (a few hundred bytes) and bounds what a bad file costs.
  constexpr std::size_t kMaxHeader = 1 << 16;
  std::string head(kMaxHeader, '\0');
  {
    std::ifstream in(f.full, std::ios::binary);
    if (!in) bad(f, "could not be opened");
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(in.gcount()));
  }
  if (head.compare(0, 7, "NRRD000") != 0 || head.size() < 8 || head[7] < '1' || head[7] > '5') {
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
  d.bytes = read_gz_payload(reader, f, d.dims, d.type);
  return d;
}

VolumeFileData read_inr_volume(const VolumeFileRef& f, const VoxelBudget& budget) {
  const bool gz = ends_with(f.name, ".gz");
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
  d.bytes = gzr ? read_gz_payload(*gzr, f, d.dims, d.type)
                : read_plain_payload(f, offset, d.dims, d.type);
  return d;
}

std::array<double, 2> volume_data_range(const VolumeFileData& d, const VolumeFileRef& f) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  std::optional<std::size_t> bad_index;  // the first non-finite sample
  double bad_value = 0.0;
  each_sample(d, [&](std::size_t i, double v) {
    if (!std::isfinite(v)) {
      if (!bad_index) {
        bad_index = i;
        bad_value = v;
      }
      return;
    }
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  });
  if (bad_index) {
    const std::size_t nx = static_cast<std::size_t>(d.dims[0]),
                      ny = static_cast<std::size_t>(d.dims[1]);
    bad(f, "has a " + std::string(std::isnan(bad_value) ? "NaN" : "infinite") + " voxel: index " +
               std::to_string(*bad_index) + " (x " + std::to_string(*bad_index % nx) + ", y " +
               std::to_string(*bad_index / nx % ny) + ", z " +
               std::to_string(*bad_index / nx / ny) + "); voxel values must be finite");
  }
  return {lo, hi};
}

std::shared_ptr<const VolumeGrid> normalize_volume(const VolumeFileData& d,
                                                   const std::array<double, 2>& range) {
  auto g = std::make_shared<VolumeGrid>();
  g->dims = d.dims;
  g->values.resize(static_cast<std::size_t>(g->voxels()));
  const double lo = range[0], width = range[1] - range[0];
  each_sample(d, [&](std::size_t i, double v) {
    g->values[i] =
        static_cast<std::uint16_t>(std::lround(std::clamp((v - lo) / width, 0.0, 1.0) * 65535.0));
  });
  return g;
}

}  // namespace beamcast
