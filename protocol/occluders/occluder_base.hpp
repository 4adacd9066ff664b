// What every occluder kind provides, and the small types its functions
// exchange with the parser, the GPU path and the CPU reference. A kind is one
// struct in its own files here (plane, box, sphere, mesh, quad), with:
//   static constexpr std::string_view kType;   its "type" in scene JSON
//   static constexpr GpuForm kGpu;             how the GPU draws it
//   static T parse(const OccluderParse& in);   validation, JSON-pointer errors
//   Aabb bounds() const;                       world-space bounds
//   void gpu_triangles(TriangleSink&) const;   kGpu == kTriangles
//   AnalyticGpu analytic(const Vec3& eye) const;  kGpu == kAnalytic
//   std::optional<OccluderHit> intersect(o, v, t_min, t_max) const;  reference
// Dispatch over the kinds is std::visit over OccluderShape (occluders.hpp), so
// a kind that lacks one of these does not compile where it is used.
#pragma once

#include <array>
#include <limits>
#include <optional>
#include <string_view>

#include "protocol/vec.hpp"

namespace beamcast {

struct OccluderParse;  // occluder_parse.hpp

// Slab test of the ray o + t v against `box`: the entry and exit parameters
// and the axes that produced them (-1: none). False when the ray misses.
bool ray_box(const Vec3& o, const Vec3& v, const Aabb& box, double* t_near, double* t_far,
             int* axis_near, int* axis_far);

// How the GPU path draws a kind: as triangles, rasterized (shaders/surface.*),
// or ray-traced per pixel (shaders/analytic_occluder.frag: planes and spheres).
// kPoints: sampled as points by its own pass (SLIM surfaces, render/slim_pass.cpp).
enum class GpuForm { kTriangles, kAnalytic, kPoints };

// Takes a triangles kind's world-space triangles. One-sided triangles are
// visible (and occlude) only from the side their normal cross(b - a, c - a)
// points to; two-sided ones from both.
class TriangleSink {
 public:
  virtual void add(const Vec3& a, const Vec3& b, const Vec3& c, bool one_sided) = 0;

 protected:
  ~TriangleSink() = default;
};

// An analytic kind's record for analytic_occluder.frag, camera-relative and
// computed in double: a.xyz a point (a.w a radius), b.xyz a unit normal, b.w
// the shader's shape code (0 plane, 1 sphere).
struct AnalyticGpu {
  std::array<double, 4> a{};
  std::array<double, 4> b{};
};

// A hit of a reference ray p(t) = o + t v: its parameter and the surface's
// unit geometric normal (not yet turned toward the viewer).
struct OccluderHit {
  double t = 0.0;
  Vec3 n{};
};

}  // namespace beamcast
