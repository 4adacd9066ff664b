// The "specular" pass's rays on the GPU (issue 39, item 4;
// shaders/specular_trace.comp): what LitShading (gi/photon_gather.hpp)
// computes on the CPU, in float, from buffers built here once per request:
// the analytic occluders (planes, spheres) and quad lights as records, the
// triangle kinds' triangles (boxes, quads, meshes) under a BVH, the photon
// maps in two hashed uniform grids (the global map's with its splat radius
// as the cell, the caustic map's with its own), the lights' direct points
// (gi.direct "shadow_maps", visibility by shadow rays on the same
// structures). Positions are relative to an anchor at the centre of the
// scene's bounds, so float keeps the scene's precision however far it lies
// from the origin.
#pragma once

#include <cstdint>
#include <vector>

#include "gi/photon_map.hpp"
#include "protocol/scene.hpp"
#include "render/gl_util.hpp"

namespace beamcast {

// Whether the GPU tracer covers `scene`: no SLIM occluders (their surface
// is sampled by points) and no medium (the segments beyond a mirror or glass
// would be attenuated). Other scenes are traced on the CPU. Both gi.direct
// methods are covered: with "shadow_maps" the diffuse surfaces a ray reaches
// show the direct points' light with shadow rays, as on the CPU.
bool gpu_traces_specular(const Scene& scene);

// A BVH over triangles (the GL-free part, for tests): nodes in depth-first
// order, an inner node's children at `first` and first + 1, a leaf's
// triangles [first, first + count) of the reordered list.
struct SpecularBvhNode {
  float lo[3];
  std::int32_t first;
  float hi[3];
  std::int32_t count;  // 0: an inner node
};
static_assert(sizeof(SpecularBvhNode) == 32, "std430 layout of BvhNode");

class SpecularGpu {
 public:
  // SSBO binding points of shaders/specular_trace.comp.
  enum Binding : GLuint {
    kShapes = 1,
    kMaterials = 2,
    kNodes = 3,
    kTriangles = 4,
    kPhotons = 5,
    kCells = 6,
    kDirect = 7
  };
  // `skip_direct`: leave out the photons straight from a light (the direct
  // pass carries that light), as PhotonGather does. Throws GlError when a
  // buffer would exceed the driver's largest shader storage block.
  SpecularGpu(const Scene& scene, const PhotonMaps& maps, bool skip_direct);
  // Binds the buffers and sets every uniform but u_eye and u_view on the
  // bound program `program`.
  void bind(GLuint program) const;
  const Vec3& anchor() const { return anchor_; }

 private:
  struct Grid {
    float origin[3] = {0.0f, 0.0f, 0.0f};
    float inv_cell = 0.0f;
    float radius = 0.0f;
    std::int32_t base = 0;  // first entry of its table in the cell buffer
    std::int32_t mask = -1; // table size - 1 (a power of two); -1: no photons
  };
  Vec3 anchor_{};
  float eps_ = 1e-4f;
  float background_[3] = {0.0f, 0.0f, 0.0f};
  int shape_count_ = 0, node_count_ = 0, direct_count_ = 0;
  int kernel_ = 2;
  Grid grids_[2];
  GlBuffer shapes_, materials_, nodes_, triangles_, photons_, cells_, direct_;
};

}  // namespace beamcast
