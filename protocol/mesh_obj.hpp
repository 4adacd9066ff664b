// Wavefront OBJ meshes as occluders: safe path resolution below an assets
// directory, parsing with tinyobjloader, triangulation and the object-to-world
// transform. Errors are ProtocolError with the JSON pointer given by the caller.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "protocol/scene.hpp"

namespace beamcast {

// world = translate + rotate(rotation, scale * v), scale per axis.
struct MeshTransform {
  Vec3 translate{0.0, 0.0, 0.0};
  Vec3 scale{1.0, 1.0, 1.0};
  std::array<double, 4> rotation{1.0, 0.0, 0.0, 0.0};  // unit quaternion w, x, y, z

  Vec3 apply(const Vec3& v) const;
};

struct MeshLoadLimits {
  std::int64_t max_triangles = 2000000;  // for the whole scene (limit max_mesh_triangles)
  std::int64_t triangles_before = 0;     // already used by earlier meshes of the scene
  double max_abs_coordinate = 1e12;      // bound on every world-space vertex coordinate
};

// The file named `file` (as written in the scene) below `assets_dir`. Refuses
// (code "forbidden_path") an empty assets_dir, absolute paths, ".." components
// and paths that leave assets_dir through a symlink; "file_not_found" if it is
// not a readable regular file. `json_path` is the pointer reported in errors;
// `what` names the kind of file in messages ("mesh", "volume").
std::filesystem::path resolve_asset_path(const std::filesystem::path& assets_dir,
                                         const std::string& file, const std::string& json_path,
                                         std::string_view what = "mesh");

// Parses OBJ text (materials and "mtllib" are ignored), triangulates polygons,
// transforms vertices to world space. Throws "bad_mesh" (parse error, index
// out of range, no triangles, non-finite vertex), "limit_exceeded"
// (max_mesh_triangles) or "out_of_range" (a world vertex beyond max_abs_coordinate).
MeshOccluder mesh_from_obj_text(const std::string& obj_text, const std::string& file,
                                const MeshTransform& xf, const MeshLoadLimits& limits,
                                const std::string& json_path);

// resolve_asset_path + read + mesh_from_obj_text.
MeshOccluder load_obj_mesh(const std::filesystem::path& assets_dir, const std::string& file,
                           const MeshTransform& xf, const MeshLoadLimits& limits,
                           const std::string& json_path);

}  // namespace beamcast
