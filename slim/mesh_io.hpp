// Triangle meshes read for the SLIM fitter (issue 16): OFF, OBJ (through
// protocol/mesh_obj's streaming reader) and PLY (ascii and
// binary_little_endian). Polygons are triangulated as fans. Errors are
// std::runtime_error naming the file and the line (text) or the element
// (binary) that is wrong.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "protocol/vec.hpp"

namespace beamcast::slim {

struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;

  Aabb bounds() const;
};

// The file's format from its extension (.off, .obj, .ply, any case).
TriangleMesh read_mesh(const std::filesystem::path& path);

// Parsers of a file's contents; `name` is used in messages.
TriangleMesh read_off(const std::string& text, const std::string& name);
TriangleMesh read_obj(const std::string& text, const std::string& name);
TriangleMesh read_ply(const std::string& bytes, const std::string& name);

}  // namespace beamcast::slim
