// What the volume-file readers (protocol/volume_formats/*.cpp) share: the
// "bad_volume" error, reading exactly the voxel bytes a header promises from
// a plain file or a compressed stream, and the small text parsing of
// headers. Internal to protocol/.
#pragma once

#include <zlib.h>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/volume_files.hpp"

namespace beamcast::volume_io {

// "[64, 64, 64]" and "\"name\"", for messages.
std::string dims_text(const std::array<std::int64_t, 3>& d);
std::string quoted(const std::string& name);

// "bad_volume" at the file's JSON path: "volume file \"name\" <why>".
[[noreturn]] void bad(const VolumeFileRef& f, const std::string& why);

// "its dimensions [64, 64, 64] of float32 (4 bytes each)", for size messages.
std::string layout_text(const std::array<int, 3>& dims, VolumeSampleType t);
std::uint64_t payload_bytes(const std::array<int, 3>& dims, VolumeSampleType t);

// Exactly the voxel bytes from offset `offset` of a plain file: its size is
// checked first, so a wrong size allocates nothing.
std::vector<unsigned char> read_plain_payload(const VolumeFileRef& f, std::uint64_t offset,
                                              const std::array<int, 3>& dims, VolumeSampleType t);

// A stream of decompressed bytes.
class ByteStream {
 public:
  virtual ~ByteStream() = default;
  // Up to n bytes; fewer only at the end of the data.
  virtual std::size_t read(unsigned char* out, std::size_t n) = 0;
};

// A gzip stream being read (zlib's gz* interface), closed on destruction.
class GzReader : public ByteStream {
 public:
  GzReader(gzFile gz, const VolumeFileRef& f);
  GzReader(const GzReader&) = delete;
  GzReader& operator=(const GzReader&) = delete;
  ~GzReader() override;
  bool direct();
  std::size_t read(unsigned char* out, std::size_t n) override;

 private:
  gzFile gz_;
  const VolumeFileRef& f_;
};

// Exactly the voxel data from a decompressed stream and nothing after it;
// `what` names the compression in messages ("gzip", "zlib").
std::vector<unsigned char> read_stream_payload(ByteStream& in, const VolumeFileRef& f,
                                               const std::array<int, 3>& dims,
                                               VolumeSampleType t, std::string_view what);

// The file's first `n` bytes (fewer if it is shorter), decompressed when it
// is gzip-compressed: what a format's signature test looks at.
std::string file_head(const VolumeFileRef& f, std::size_t n);
// The first `max_bytes` bytes of a plain file (fewer if it is shorter).
std::string read_prefix(const VolumeFileRef& f, std::size_t max_bytes);

bool ends_with(const std::string& s, std::string_view suffix);
std::string trim(std::string_view s);
std::vector<std::string> words(std::string_view s);
std::optional<std::int64_t> parse_int(std::string_view s);
std::optional<double> parse_double(std::string_view s);
// Lines without their '\n' (and '\r').
std::vector<std::string> lines(std::string_view text);

// A header spacing: > 0 and finite; `nan` (NRRD: "no spacing") reads as 1.
double header_spacing(const VolumeFileRef& f, const std::string& field, const std::string& s);
// A header's dimensions checked as check_volume_dims does, every error at
// the file's JSON path; `what` names the header field ("sizes").
std::array<int, 3> header_dims(const VolumeFileRef& f, const std::array<std::int64_t, 3>& dims,
                               const VoxelBudget& budget, const std::string& what);

}  // namespace beamcast::volume_io
