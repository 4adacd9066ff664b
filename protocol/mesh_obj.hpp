// Wavefront OBJ meshes as occluders: a streaming reader that counts as it goes
// (positions and faces; every other statement is ignored), triangulation and
// the object-to-world transform. Errors are ProtocolError with the JSON pointer
// given by the caller; messages about the file's contents name its line.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "protocol/asset_files.hpp"
#include "protocol/scene.hpp"
#include "protocol/scene_json.hpp"

namespace beamcast {

// world = translate + rotate(rotation, scale * v), scale per axis.
struct MeshTransform {
  Vec3 translate{0.0, 0.0, 0.0};
  Vec3 scale{1.0, 1.0, 1.0};
  std::array<double, 4> rotation{1.0, 0.0, 0.0, 0.0};  // unit quaternion w, x, y, z

  Vec3 apply(const Vec3& v) const;
};

struct MeshLoadLimits {
  // For the whole scene (limit max_mesh_triangles); defaults: the offline
  // SceneLimits' (protocol/scene_json.hpp), not a copy of their numbers.
  std::int64_t max_triangles = SceneLimits{}.max_mesh_triangles;
  std::int64_t triangles_before = 0;  // already used by earlier meshes of the scene
  double max_abs_coordinate = SceneLimits{}.max_abs_coordinate;  // every world-space vertex coordinate
};

// Bytes an OBJ file may have per triangle the scene still has room for, plus
// kObjBaseBytes: a face with normals and texture coordinates and its share of
// the v/vn/vt lines take about 120, so 256 is twice that; the size is checked
// before a byte is read.
inline constexpr std::uint64_t kObjBytesPerTriangle = 256;
inline constexpr std::uint64_t kObjBaseBytes = 1u << 20;
// Longest line read (a face of a few thousand vertices).
inline constexpr std::size_t kObjMaxLineBytes = 1u << 16;

// Parses OBJ text ("v" and "f" lines; normals, texture coordinates, groups,
// materials and "mtllib" are ignored), triangulates polygons (a quad along its
// shorter diagonal, larger ones as a fan), transforms vertices to world space.
// Throws, at the first line that breaks a rule, "bad_mesh" (a malformed or
// non-finite number, an index that is 0, not an integer, or not one of the
// vertices defined before it, a face of fewer than 3 vertices; no triangles at
// all), "limit_exceeded" (max_mesh_triangles, or more than 3 vertices per
// triangle it allows) or "out_of_range" (a world vertex beyond
// max_abs_coordinate); messages name the file and line.
MeshOccluder mesh_from_obj_text(const std::string& obj_text, const std::string& file,
                                const MeshTransform& xf, const MeshLoadLimits& limits,
                                const std::string& json_path);

// The same, streamed from the file below `assets_dir` (AssetFile's rules; at
// most kObjBaseBytes + kObjBytesPerTriangle per triangle left, checked before
// reading), stopping at the first limit crossed.
MeshOccluder load_obj_mesh(const std::filesystem::path& assets_dir, const std::string& file,
                           const MeshTransform& xf, const MeshLoadLimits& limits,
                           const std::string& json_path);

}  // namespace beamcast
