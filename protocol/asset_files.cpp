#include "protocol/asset_files.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <system_error>

#include "protocol/errors.hpp"

namespace beamcast {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const char* code, const std::string& path, std::string message) {
  throw ProtocolError(ErrorInfo{code, std::move(message), path});
}

// True if `p` equals `root` or lies below it (both already canonical).
bool is_within(const fs::path& root, const fs::path& p) {
  auto r = root.begin();
  auto q = p.begin();
  for (; r != root.end(); ++r, ++q) {
    if (r->empty()) continue;  // trailing "" element of a path ending in '/'
    if (q == p.end() || *r != *q) return false;
  }
  return true;
}

[[noreturn]] void refuse_outside(const std::string& kind, const std::string& file, const std::string& json_path) {
  fail("forbidden_path", json_path,
       kind + " path \"" + file + "\" resolves to a file outside the assets directory");
}

[[noreturn]] void refuse_special(const std::string& kind, const std::string& file, const std::string& json_path) {
  fail("forbidden_path", json_path,
       kind + " file \"" + file + "\" is not a regular file (a directory, FIFO, socket or device)");
}

}  // namespace

fs::path resolve_asset_path(const fs::path& assets_dir, const std::string& file,
                            const std::string& json_path, std::string_view what) {
  const std::string kind(what);
  if (assets_dir.empty()) {
    fail("forbidden_path", json_path,
         kind + " files are disabled here (no assets directory configured), cannot load \"" +
             file + "\"");
  }
  if (file.find('\0') != std::string::npos) {
    fail("forbidden_path", json_path, kind + " path must not contain NUL characters");
  }
  const fs::path rel(file);
  if (rel.is_absolute() || rel.has_root_name() || rel.has_root_directory()) {
    fail("forbidden_path", json_path,
         kind + " path must be relative to the assets directory, got absolute path \"" + file +
             "\"");
  }
  for (const auto& part : rel) {
    if (part == "..") {
      fail("forbidden_path", json_path,
           kind + " path must not contain \"..\" components, got \"" + file + "\"");
    }
  }
  const fs::path full = assets_dir / rel;
  std::error_code ec;
  const fs::file_status st = fs::status(full, ec);  // follows links
  if (!fs::exists(st)) {
    // Where the file must be is the caller's setting, not the client's: say so.
    fail("file_not_found", json_path,
         kind + " file \"" + file +
             "\" was not found in the assets directory (beamcast-server reads mesh, SLIM and "
             "volume files from its --assets directory, examples/ by default: copy the file "
             "there or restart the server with --assets DIR; `beamcast render` reads them "
             "beside the scene file, or from --assets DIR)");
  }
  // Symlinks inside the assets directory must not lead out of it (checked
  // before the type: a link out is refused as such, whatever it points to).
  const fs::path root = fs::canonical(assets_dir, ec);
  const fs::path target = ec ? fs::path() : fs::canonical(full, ec);
  if (ec || !is_within(root, target)) refuse_outside(kind, file, json_path);
  if (!fs::is_regular_file(st)) refuse_special(kind, file, json_path);
  return full;
}

AssetFile::AssetFile(const fs::path& assets_dir, const std::string& file,
                     const std::string& json_path, std::string_view what, std::uint64_t max_bytes,
                     std::string_view limit_text)
    : name_(file), json_path_(json_path), what_(what), max_bytes_(max_bytes) {
  const fs::path full = resolve_asset_path(assets_dir, file, json_path, what);
  // O_NONBLOCK: opening a FIFO put in place after the check must not wait for a writer.
  const int fd = ::open(full.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) fail("file_not_found", json_path, what_ + " file \"" + file + "\" cannot be opened");
  f_.reset(::fdopen(fd, "rb"));
  if (!f_) {
    ::close(fd);
    fail("file_not_found", json_path, what_ + " file \"" + file + "\" cannot be opened");
  }
  // The rules again on what was opened: the path may have changed since.
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) refuse_special(what_, file, json_path);
  std::error_code ec_link, ec_root;
  const fs::path opened = fs::read_symlink("/proc/self/fd/" + std::to_string(fd), ec_link);
  const fs::path root = fs::canonical(assets_dir, ec_root);
  if (ec_link || ec_root || !is_within(root, opened)) refuse_outside(what_, file, json_path);
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  size_ = static_cast<std::uint64_t>(st.st_size);
  if (size_ > max_bytes) {
    fail("limit_exceeded", json_path,
         what_ + " file \"" + file + "\" is " + std::to_string(size_) + " bytes, over the " +
             std::to_string(max_bytes) + " bytes that " + std::string(limit_text));
  }
}

bool AssetFile::read_line(std::string* out, std::size_t max_line, const char* too_long_code) {
  out->clear();
  std::FILE* f = f_.get();
  int c = getc_unlocked(f);
  if (c == EOF) return false;
  ++line_;
  for (; c != EOF && c != '\n'; c = getc_unlocked(f)) {
    if (++read_ > max_bytes_) {
      fail("limit_exceeded", json_path_,
           what_ + " file \"" + name_ + "\" grew past " + std::to_string(max_bytes_) +
               " bytes while it was read");
    }
    if (out->size() == max_line) {
      fail(too_long_code, json_path_,
           what_ + " file \"" + name_ + "\", line " + std::to_string(line_) +
               ": longer than " + std::to_string(max_line) + " bytes");
    }
    out->push_back(static_cast<char>(c));
  }
  if (c == '\n') ++read_;
  if (!out->empty() && out->back() == '\r') out->pop_back();
  if (std::ferror(f)) {
    fail("file_not_found", json_path_, what_ + " file \"" + name_ + "\" could not be read");
  }
  return true;
}

std::string AssetFile::read_all() {
  std::string text(static_cast<std::size_t>(size_), '\0');
  const std::size_t n = std::fread(text.data(), 1, text.size(), f_.get());
  if (std::ferror(f_.get())) {
    fail("file_not_found", json_path_, what_ + " file \"" + name_ + "\" could not be read");
  }
  text.resize(n);  // shorter if it shrank meanwhile; never longer than checked
  return text;
}

}  // namespace beamcast
