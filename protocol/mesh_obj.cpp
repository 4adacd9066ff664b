#include "protocol/mesh_obj.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string_view>
#include <vector>

#include "protocol/camera.hpp"
#include "protocol/errors.hpp"

namespace beamcast {

namespace fs = std::filesystem;

namespace {

constexpr std::int64_t kI64Max = std::numeric_limits<std::int64_t>::max();

std::int64_t saturating_mul(std::int64_t a, std::int64_t b) {
  return a > 0 && b > kI64Max / a ? kI64Max : a * b;
}

std::string clip(std::string_view s) {
  return s.size() <= 40 ? std::string(s) : std::string(s.substr(0, 40)) + "...";
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

// Splits a line into whitespace-separated tokens (views into the line).
void split(std::string_view line, std::vector<std::string_view>* out) {
  out->clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const std::size_t b = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > b) out->push_back(line.substr(b, i - b));
  }
}

// Reads an OBJ one line at a time, counting vertices and triangles as it goes
// and failing at the first line over a limit, so a file far over them costs
// no more than the lines up to that one.
class ObjReader {
 public:
  ObjReader(const std::string& file, const MeshTransform& xf, const MeshLoadLimits& limits,
            const std::string& json_path)
      : file_(file),
        xf_(xf),
        limits_(limits),
        json_path_(json_path),
        // Indices are 32-bit: no more vertices than they can name.
        max_vertices_(std::min<std::int64_t>(
            saturating_mul(3, std::max<std::int64_t>(0, limits.max_triangles - limits.triangles_before)),
            std::numeric_limits<std::uint32_t>::max())) {
    mesh_.file = file;
  }

  void line(std::string_view text) {
    ++line_no_;
    split(text, &tokens_);
    if (tokens_.empty() || tokens_[0].front() == '#') return;
    if (tokens_[0] == "v") {
      vertex();
    } else if (tokens_[0] == "f") {
      face();
    }
    // Everything else (vn, vt, vp, l, p, o, g, s, usemtl, mtllib, vw, ...) is
    // not needed for an occluder and is skipped unread.
  }

  MeshOccluder finish() {
    if (mesh_.triangles.empty()) {
      throw ProtocolError(
          ErrorInfo{"bad_mesh", "mesh file \"" + file_ + "\" contains no triangles", json_path_});
    }
    return std::move(mesh_);
  }

 private:
  [[noreturn]] void fail(const char* code, const std::string& what) const {
    throw ProtocolError(ErrorInfo{
        code, "mesh file \"" + file_ + "\", line " + std::to_string(line_no_) + ": " + what,
        json_path_});
  }

  double number(std::string_view t) const {
    std::string_view s = t;
    if (s.size() > 1 && s[0] == '+') s.remove_prefix(1);  // from_chars takes no '+'
    double v = 0.0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (end != s.data() + s.size() || (ec != std::errc() && ec != std::errc::result_out_of_range)) {
      fail("bad_mesh", "\"" + clip(t) + "\" is not a number");
    }
    if (ec == std::errc::result_out_of_range) {
      v = std::strtod(std::string(s).c_str(), nullptr);  // an underflow is a fine 0 or denormal
    }
    if (!std::isfinite(v)) fail("bad_mesh", "coordinate \"" + clip(t) + "\" is not a finite number");
    return v;
  }

  void vertex() {
    if (tokens_.size() < 4) fail("bad_mesh", "a vertex (\"v\") needs x, y and z");
    const Vec3 v{number(tokens_[1]), number(tokens_[2]), number(tokens_[3])};
    if (static_cast<std::int64_t>(mesh_.vertices.size()) >= max_vertices_) {
      fail("limit_exceeded",
           "more than " + std::to_string(max_vertices_) +
               " vertices, 3 for each triangle the limit max_mesh_triangles = " +
               std::to_string(limits_.max_triangles) + " leaves room for");
    }
    const Vec3 w = xf_.apply(v);
    for (double c : w) {
      if (!(std::abs(c) <= limits_.max_abs_coordinate)) {
        fail("out_of_range", "vertex " + std::to_string(mesh_.vertices.size() + 1) +
                                 " lies beyond max_abs_coordinate after the transform");
      }
    }
    mesh_.vertices.push_back(w);
  }

  // A face corner "i", "i/t", "i//n" or "i/t/n": the position index, 1-based,
  // negative counting back from the last vertex defined so far.
  std::uint32_t corner(std::string_view t) const {
    const std::string_view s = t.substr(0, t.find('/'));
    std::int64_t k = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), k);
    const auto n = static_cast<std::int64_t>(mesh_.vertices.size());
    if (s.empty() || end != s.data() + s.size() || ec != std::errc()) {
      fail("bad_mesh", "face index \"" + clip(t) + "\" is not an integer in range");
    }
    if (k == 0) fail("bad_mesh", "face index 0 (OBJ indices start at 1; negative ones count back)");
    const std::int64_t i = k > 0 ? k - 1 : n + k;
    if (i < 0 || i >= n) {
      fail("bad_mesh", "face index " + std::to_string(k) + " is out of range: " +
                           std::to_string(n) + " vertices are defined before this line");
    }
    return static_cast<std::uint32_t>(i);
  }

  void face() {
    const std::size_t fv = tokens_.size() - 1;
    if (fv < 3) fail("bad_mesh", "a face needs at least 3 vertices, got " + std::to_string(fv));
    idx_.clear();
    for (std::size_t k = 1; k <= fv; ++k) idx_.push_back(corner(tokens_[k]));
    if (static_cast<std::int64_t>(fv - 2) > limits_.max_triangles - triangles_total()) {
      fail("limit_exceeded", "the mesh brings the scene over the limit max_mesh_triangles = " +
                                 std::to_string(limits_.max_triangles) + " triangles");
    }
    auto& t = mesh_.triangles;
    if (fv == 4) {
      // Along the shorter diagonal, as tinyobjloader (the earlier reader) did.
      const auto& v = mesh_.vertices;
      if (length(v[idx_[2]] - v[idx_[0]]) < length(v[idx_[3]] - v[idx_[1]])) {
        t.push_back({idx_[0], idx_[1], idx_[2]});
        t.push_back({idx_[0], idx_[2], idx_[3]});
      } else {
        t.push_back({idx_[0], idx_[1], idx_[3]});
        t.push_back({idx_[1], idx_[2], idx_[3]});
      }
      return;
    }
    for (std::size_t k = 1; k + 1 < fv; ++k) t.push_back({idx_[0], idx_[k], idx_[k + 1]});
  }

  std::int64_t triangles_total() const {
    return limits_.triangles_before + static_cast<std::int64_t>(mesh_.triangles.size());
  }

  const std::string& file_;
  const MeshTransform& xf_;
  const MeshLoadLimits& limits_;
  const std::string& json_path_;
  const std::int64_t max_vertices_;
  MeshOccluder mesh_;
  std::size_t line_no_ = 0;
  std::vector<std::string_view> tokens_;
  std::vector<std::uint32_t> idx_;
};

}  // namespace

Vec3 MeshTransform::apply(const Vec3& v) const {
  return translate + rotate(rotation, Vec3{scale[0] * v[0], scale[1] * v[1], scale[2] * v[2]});
}

MeshOccluder mesh_from_obj_text(const std::string& obj_text, const std::string& file,
                                const MeshTransform& xf, const MeshLoadLimits& limits,
                                const std::string& json_path) {
  ObjReader reader(file, xf, limits, json_path);
  const std::string_view text(obj_text);
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t eol = text.find('\n', pos);
    if (eol == std::string_view::npos) eol = text.size();
    reader.line(text.substr(pos, eol - pos));
    pos = eol + 1;
  }
  return reader.finish();
}

MeshOccluder load_obj_mesh(const fs::path& assets_dir, const std::string& file,
                           const MeshTransform& xf, const MeshLoadLimits& limits,
                           const std::string& json_path) {
  const std::int64_t room = limits.max_triangles - limits.triangles_before;
  const auto max_bytes = static_cast<std::uint64_t>(
      std::min(kI64Max - static_cast<std::int64_t>(kObjBaseBytes),
               saturating_mul(static_cast<std::int64_t>(kObjBytesPerTriangle), room)) +
      static_cast<std::int64_t>(kObjBaseBytes));
  AssetFile in(assets_dir, file, json_path, "mesh", max_bytes,
               "max_mesh_triangles = " + std::to_string(limits.max_triangles) + " allows (" +
                   std::to_string(kObjBytesPerTriangle) + " a triangle left + 1 MiB)");
  ObjReader reader(file, xf, limits, json_path);
  std::string line;
  while (in.read_line(&line, kObjMaxLineBytes, "bad_mesh")) reader.line(line);
  return reader.finish();
}

}  // namespace beamcast
