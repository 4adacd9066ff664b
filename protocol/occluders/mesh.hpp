// Occluder "mesh": an OBJ file from the assets directory, transformed to world
// space when the scene is loaded (renderers never touch files), rasterized as
// two-sided triangles.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "protocol/occluders/occluder_base.hpp"

namespace beamcast {

struct MeshOccluder {
  static constexpr std::string_view kType = "mesh";
  static constexpr GpuForm kGpu = GpuForm::kTriangles;
  std::string file;  // as named in the scene, for messages
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  // The vertices' bounds, set by parse; a mesh built by hand leaves it empty
  // and the reference then tests every triangle.
  Aabb box;
  // Names the vertices and triangles (mesh_content_key), set by parse: the
  // renderer's key for the uploaded triangles (render/scene_resources.hpp).
  // Empty for a mesh built by hand: the renderer then computes it.
  std::string content_key;

  static MeshOccluder parse(const OccluderParse& in);
  Aabb bounds() const;
  void gpu_triangles(TriangleSink& out) const;
  std::optional<OccluderHit> intersect(const Vec3& o, const Vec3& v, double t_min,
                                       double t_max) const;
};

// The counts of vertices and triangles and a 64-bit hash (std::hash over
// the bytes) of each.
std::string mesh_content_key(const MeshOccluder& mesh);

}  // namespace beamcast
