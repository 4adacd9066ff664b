#include "protocol/volume_formats/format_support.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <system_error>

#include "protocol/json_reader.hpp"

namespace beamcast::volume_io {

using json_read::fail;

std::string dims_text(const std::array<std::int64_t, 3>& d) {
  return "[" + std::to_string(d[0]) + ", " + std::to_string(d[1]) + ", " + std::to_string(d[2]) +
         "]";
}

std::string quoted(const std::string& name) { return "\"" + name + "\""; }

void bad(const VolumeFileRef& f, const std::string& why) {
  fail("bad_volume", f.json_path, "volume file " + quoted(f.name) + " " + why);
}

std::string layout_text(const std::array<int, 3>& dims, VolumeSampleType t) {
  return "its dimensions " + dims_text({dims[0], dims[1], dims[2]}) + " of " +
         std::string(sample_type_name(t)) + " (" + std::to_string(sample_size(t)) +
         (sample_size(t) == 1 ? " byte" : " bytes") + " each)";
}

std::uint64_t payload_bytes(const std::array<int, 3>& dims, VolumeSampleType t) {
  return static_cast<std::uint64_t>(dims[0]) * dims[1] * dims[2] * sample_size(t);
}

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

GzReader::GzReader(gzFile gz, const VolumeFileRef& f) : gz_(gz), f_(f) {
  if (!gz_) bad(f_, "could not be opened");
  gzbuffer(gz_, 1 << 17);
}

GzReader::~GzReader() { gzclose(gz_); }

bool GzReader::direct() { return gzdirect(gz_) != 0; }

std::size_t GzReader::read(unsigned char* out, std::size_t n) {
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

std::vector<unsigned char> read_stream_payload(ByteStream& in, const VolumeFileRef& f,
                                               const std::array<int, 3>& dims,
                                               VolumeSampleType t, std::string_view what) {
  const std::uint64_t expected = payload_bytes(dims, t);
  std::vector<unsigned char> bytes(expected);
  const std::size_t got = in.read(bytes.data(), bytes.size());
  if (got < expected) {
    bad(f, "is too short: " + layout_text(dims, t) + " need " + std::to_string(expected) +
               " bytes of voxel data, its " + std::string(what) + " data holds " +
               std::to_string(got));
  }
  unsigned char extra;
  if (in.read(&extra, 1) != 0) {
    bad(f, "is longer than its header says: " + layout_text(dims, t) + " need " +
               std::to_string(expected) + " bytes of voxel data, its " + std::string(what) +
               " data holds more");
  }
  return bytes;
}

std::string file_head(const VolumeFileRef& f, std::size_t n) {
  // gzread passes a file that is not gzip through as it is.
  GzReader in(gzopen(f.full.c_str(), "rb"), f);
  std::string head(n, '\0');
  head.resize(in.read(reinterpret_cast<unsigned char*>(head.data()), n));
  return head;
}

std::string read_prefix(const VolumeFileRef& f, std::size_t max_bytes) {
  std::string head(max_bytes, '\0');
  std::ifstream in(f.full, std::ios::binary);
  if (!in) bad(f, "could not be opened");
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return head;
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

double header_spacing(const VolumeFileRef& f, const std::string& field, const std::string& s) {
  const auto v = parse_double(s);
  if (v && std::isnan(*v)) return 1.0;
  if (!v || !(*v > 0.0) || !std::isfinite(*v)) {
    bad(f, "has a bad " + field + " \"" + s + "\" (spacings must be numbers > 0)");
  }
  return *v;
}

std::array<int, 3> header_dims(const VolumeFileRef& f, const std::array<std::int64_t, 3>& dims,
                               const VoxelBudget& budget, const std::string& what) {
  return check_volume_dims(dims, budget, quoted(f.name) + "'s " + what,
                           {f.json_path, f.json_path, f.json_path}, f.json_path);
}

}  // namespace beamcast::volume_io
