#include "protocol/mesh_obj.hpp"

#include <tiny_obj_loader.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>
#include <system_error>

#include "protocol/camera.hpp"
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

// tinyobjloader parses "vw" (per-vertex joint weights, its own extension) and
// converts the joint id with int(float), undefined behaviour for huge values
// (found by fuzz_obj, docs/fuzzing.md). Occluders use positions and faces only,
// so those lines are blanked (kept as empty lines: error line numbers stay right).
std::string without_vertex_weights(const std::string& text) {
  std::string out = text;
  std::size_t pos = 0;
  while (pos < out.size()) {
    std::size_t eol = out.find('\n', pos);
    if (eol == std::string::npos) eol = out.size();
    std::size_t p = pos;
    while (p < eol && (out[p] == ' ' || out[p] == '\t')) ++p;
    if (eol - p >= 3 && out[p] == 'v' && out[p + 1] == 'w' && (out[p + 2] == ' ' || out[p + 2] == '\t')) {
      out.erase(pos, eol - pos);
      eol = pos;
    }
    pos = eol + 1;
  }
  return out;
}

std::string first_line(const std::string& s) {
  const auto nl = s.find('\n');
  return nl == std::string::npos ? s : s.substr(0, nl);
}

}  // namespace

Vec3 MeshTransform::apply(const Vec3& v) const {
  return translate + rotate(rotation, Vec3{scale[0] * v[0], scale[1] * v[1], scale[2] * v[2]});
}

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
  if (!fs::is_regular_file(full, ec)) {
    fail("file_not_found", json_path,
         kind + " file \"" + file + "\" was not found in the assets directory");
  }
  // Symlinks inside the assets directory must not lead out of it.
  const fs::path root = fs::canonical(assets_dir, ec);
  const fs::path target = ec ? fs::path() : fs::canonical(full, ec);
  if (ec || !is_within(root, target)) {
    fail("forbidden_path", json_path,
         kind + " path \"" + file + "\" resolves to a file outside the assets directory");
  }
  return full;
}

MeshOccluder mesh_from_obj_text(const std::string& obj_text, const std::string& file,
                                const MeshTransform& xf, const MeshLoadLimits& limits,
                                const std::string& json_path) {
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  // Parsing from a string (not a file) keeps "mtllib" from opening other files.
  if (!reader.ParseFromString(without_vertex_weights(obj_text), std::string(), config)) {
    fail("bad_mesh", json_path,
         "mesh file \"" + file + "\" is not a valid OBJ file: " + first_line(reader.Error()));
  }
  const auto& positions = reader.GetAttrib().vertices;
  const std::size_t vertex_count = positions.size() / 3;

  MeshOccluder mesh;
  mesh.file = file;
  mesh.vertices.reserve(vertex_count);
  for (std::size_t i = 0; i < vertex_count; ++i) {
    const Vec3 v{static_cast<double>(positions[3 * i]), static_cast<double>(positions[3 * i + 1]),
                 static_cast<double>(positions[3 * i + 2])};
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {
      fail("bad_mesh", json_path,
           "mesh file \"" + file + "\" has a non-finite coordinate in vertex " +
               std::to_string(i + 1));
    }
    const Vec3 w = xf.apply(v);
    for (double c : w) {
      if (!(std::abs(c) <= limits.max_abs_coordinate)) {
        fail("out_of_range", json_path,
             "mesh file \"" + file + "\" vertex " + std::to_string(i + 1) +
                 " lies beyond max_abs_coordinate after the transform");
      }
    }
    mesh.vertices.push_back(w);
  }

  std::int64_t total = limits.triangles_before;
  for (const auto& shape : reader.GetShapes()) {
    std::size_t offset = 0;
    for (const unsigned char fv_raw : shape.mesh.num_face_vertices) {
      const std::size_t fv = fv_raw;
      if (offset + fv > shape.mesh.indices.size()) {
        fail("bad_mesh", json_path, "mesh file \"" + file + "\" has inconsistent face data");
      }
      std::array<std::uint32_t, 256> idx{};  // fv is an unsigned char
      for (std::size_t k = 0; k < fv; ++k) {
        const int vi = shape.mesh.indices[offset + k].vertex_index;
        if (vi < 0 || static_cast<std::size_t>(vi) >= vertex_count) {
          fail("bad_mesh", json_path,
               "mesh file \"" + file + "\" has a face index out of range (" +
                   std::to_string(vi + 1) + " of " + std::to_string(vertex_count) + " vertices)");
        }
        idx[k] = static_cast<std::uint32_t>(vi);
      }
      // tinyobjloader already triangulates; fan anything it left as a polygon.
      for (std::size_t k = 1; k + 1 < fv; ++k) {
        if (++total > limits.max_triangles) {
          fail("limit_exceeded", json_path,
               "mesh file \"" + file + "\" brings the scene over the limit max_mesh_triangles = " +
                   std::to_string(limits.max_triangles) + " triangles");
        }
        mesh.triangles.push_back({idx[0], idx[k], idx[k + 1]});
      }
      offset += fv;
    }
  }
  if (mesh.triangles.empty()) {
    fail("bad_mesh", json_path, "mesh file \"" + file + "\" contains no triangles");
  }
  return mesh;
}

MeshOccluder load_obj_mesh(const fs::path& assets_dir, const std::string& file,
                           const MeshTransform& xf, const MeshLoadLimits& limits,
                           const std::string& json_path) {
  const fs::path full = resolve_asset_path(assets_dir, file, json_path);
  std::ifstream in(full, std::ios::binary);
  if (!in) {
    fail("file_not_found", json_path, "mesh file \"" + file + "\" could not be opened");
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) {
    fail("file_not_found", json_path, "mesh file \"" + file + "\" could not be read");
  }
  return mesh_from_obj_text(text.str(), file, xf, limits, json_path);
}

}  // namespace beamcast
