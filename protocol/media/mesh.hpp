// Medium region "mesh": the inside of a closed, consistently wound triangle
// mesh, from an OBJ file below the assets directory or inline (vertices,
// triangles). GPU record: code 2, a and b its bounds' corners; its
// triangles in the shader's SSBO.
#pragma once

#include "protocol/media/region_base.hpp"

namespace beamcast {

// Triangles of all mesh regions of a scene together: a shader evaluating
// optical depth tests every triangle of each mesh whose bounds the ray
// meets, several times per pixel, so a region boundary is a coarse hull
// (an icosphere of 320 triangles, a box of 12), not a detailed model.
inline constexpr std::int64_t kMaxMediumMeshTriangles = 1024;

struct MeshRegion {
  static constexpr std::string_view kType = "mesh";
  static constexpr std::array<std::string_view, 6> kFields{"vertices",  "triangles", "file",
                                                           "translate", "scale",     "rotation"};
  static constexpr int kGpuCode = 2;
  // World-space triangles of a closed, consistently wound surface, wound so
  // their normals (p1 - p0) x (p2 - p0) point outwards. Along a line the
  // region is where more boundaries were entered (against a normal) than
  // left (the seed's section 5.7: front faces enter, back faces leave); a
  // line through an edge or vertex counts one crossing there
  // (mesh_crossings in mesh.cpp).
  std::vector<std::array<Vec3, 3>> triangles;
  Aabb box;  // the triangles' bounds

  // Refuses ("bad_mesh") a mesh that is not closed and consistently wound;
  // the scene's mesh-region triangles together at most
  // kMaxMediumMeshTriangles.
  static MeshRegion parse(const RegionParse& in);
  // The region of outward-wound `tris` (not checked: tests).
  static MeshRegion from_triangles(std::vector<std::array<Vec3, 3>> tris);
  Aabb bounds() const { return box; }
  bool contains(const Vec3& x) const;
  double chord(const Vec3& o, const Vec3& v, double t0, double t1) const;
  double exit(const Vec3& o, const Vec3& v) const;
  void crossings(const Vec3& o, const Vec3& v, double t_end, std::vector<double>* out) const;
  RegionGpu gpu() const { return {kGpuCode, box.lo, box.hi, 0.0}; }
  RegionTriangles gpu_triangles() const { return triangles; }
};

}  // namespace beamcast
