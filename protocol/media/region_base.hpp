// What every medium region kind provides ("media" in scene JSON; the
// regions of protocol/medium.hpp), and the small types its functions
// exchange with the parser, the GPU path and the CPU reference. A kind is one
// struct in its own files here (box, sphere, mesh), with:
//   static constexpr std::string_view kType;   its "type" in scene JSON
//   static constexpr std::array kFields;       its own JSON keys
//   static T parse(const RegionParse& in);     validation, JSON-pointer errors
//   Aabb bounds() const;                       world-space bounds
//   bool contains(const Vec3& x) const;        membership (the CPU reference)
//   double chord(o, v, t0, t1) const;          length of o + t v inside, t in [t0, t1]
//   double exit(o, v) const;                   where o + t v last leaves (-1: never inside)
//   void crossings(o, v, t_end, out) const;    boundary crossings in (0, t_end)
//   RegionGpu gpu() const;                     its record for shaders/medium_regions.glsl
//   RegionTriangles gpu_triangles() const;     triangles for the shader's SSBO (mesh)
// A convex kind (one interval of a line inside it) derives from
// ConvexRegion<Kind> and gives clip() instead of chord, exit, crossings and
// gpu_triangles. Dispatch over the kinds is std::visit over RegionShape
// (regions.hpp), so a kind that lacks one of these does not compile where it
// is used.
#pragma once

#include <array>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <span>
#include <string_view>
#include <vector>

#include "protocol/vec.hpp"

namespace beamcast {

namespace json_read {
class ObjectReader;
}  // namespace json_read
struct SceneLoadOptions;

// What a region kind's parse function reads from: the region's JSON object
// (its keys already checked against "type", the kind's kFields and the
// coefficients), the load options (limits, assets directory) and the
// scene's running count of mesh-region triangles.
struct RegionParse {
  const json_read::ObjectReader& fields;
  const SceneLoadOptions& opts;
  std::int64_t* mesh_triangles;
};

// A kind's record for shaders/medium_regions.glsl (world space): `code` the
// shader's kind code (u_region_a's w), a and b two points (u_region_a,
// u_region_b's xyz), r a radius (u_region_r). Each kind's header says what
// its points are; the shader's region_depth has one branch per code.
struct RegionGpu {
  int code = 0;
  Vec3 a{};
  Vec3 b{};
  double r = 0.0;
};

// World-space triangles, three vertices each.
using RegionTriangles = std::span<const std::array<Vec3, 3>>;

// Slab test of o + t v against `box`: narrows [*a, *b] to the part inside
// (leaves *b <= *a when there is none).
void clip_to_box(const Aabb& box, const Vec3& o, const Vec3& v, double* a, double* b);

// chord, exit, crossings and gpu_triangles of a convex kind K from its
// K::clip(o, v, &a, &b), which narrows [a, b] to the part of o + t v inside.
template <class K>
struct ConvexRegion {
  double chord(const Vec3& o, const Vec3& v, double t0, double t1) const {
    double a = t0, b = t1;
    self().clip(o, v, &a, &b);
    return b > a ? b - a : 0.0;
  }
  double exit(const Vec3& o, const Vec3& v) const {
    double a = 0.0, b = std::numeric_limits<double>::infinity();
    self().clip(o, v, &a, &b);
    return b > a ? b : -1.0;
  }
  void crossings(const Vec3& o, const Vec3& v, double t_end, std::vector<double>* out) const {
    double a = 0.0, b = t_end;
    self().clip(o, v, &a, &b);
    if (!(b > a)) return;
    if (a > 0.0) out->push_back(a);
    if (b < t_end) out->push_back(b);
  }
  RegionTriangles gpu_triangles() const { return {}; }

 private:
  const K& self() const { return static_cast<const K&>(*this); }
};

}  // namespace beamcast
