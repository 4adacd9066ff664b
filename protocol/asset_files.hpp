// Files below the assets directory (examples/): the one rule for which of
// them a client may make the server read (mesh, SLIM and volume files of
// scenes, the preview's example scenes), and reading them within a byte limit.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

namespace beamcast {

// The file named `file` (as written in the scene) below `assets_dir`. Refuses
// (code "forbidden_path") an empty assets_dir, absolute paths, ".." components,
// paths that leave assets_dir through a symlink and anything that is not a
// regular file (a FIFO, a device, a directory); "file_not_found" if nothing is
// there. `json_path` is the pointer reported in errors; `what` names the kind
// of file in messages ("mesh", "volume").
std::filesystem::path resolve_asset_path(const std::filesystem::path& assets_dir,
                                         const std::string& file, const std::string& json_path,
                                         std::string_view what = "mesh");

// An asset file open for reading: resolve_asset_path's rules checked again on
// the opened descriptor (a regular file, really below assets_dir, so a link
// swapped after the check is caught) and its size checked against
// `max_bytes` before a byte is read ("limit_exceeded" naming `limit_text`,
// e.g. "max_mesh_triangles = 1000 allows"). Reads never go past max_bytes.
class AssetFile {
 public:
  AssetFile(const std::filesystem::path& assets_dir, const std::string& file,
            const std::string& json_path, std::string_view what, std::uint64_t max_bytes,
            std::string_view limit_text);
  std::uint64_t size() const { return size_; }
  // Next line without its '\n' (and '\r'), into `out`; false at the end. A
  // line longer than `max_line` bytes is refused ("bad_<what>"-style errors
  // are the caller's: this throws code `too_long_code`).
  bool read_line(std::string* out, std::size_t max_line, const char* too_long_code);
  // The whole file (at most max_bytes).
  std::string read_all();
  // For parsers that take a C stream (nlohmann's file input).
  std::FILE* stream() { return f_.get(); }

 private:
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, Closer> f_;
  std::string name_, json_path_, what_;
  std::uint64_t size_ = 0;
  std::uint64_t read_ = 0;  // bytes handed out so far
  std::uint64_t max_bytes_ = 0;
  std::size_t line_ = 0;
};

}  // namespace beamcast
