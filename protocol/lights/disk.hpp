// Light "disk": a one-sided Lambertian emitting disk of `radius` about
// `center`, emitting to the side `normal` points to (like the quad, whose
// front is cross(edge_u, edge_v)). Its radiance is flux / (pi area), area =
// pi radius^2; "radiance" in JSON gives it directly.
#pragma once

#include <string_view>

#include "protocol/lights/light_base.hpp"

namespace beamcast {

struct DiskLight {
  static constexpr std::string_view kType = "disk";
  static constexpr std::array<std::string_view, 4> kFields{"center", "normal", "radius",
                                                           "radiance"};
  // shaders/light_outline.glsl: the disk inscribed in the outline's square.
  static constexpr int kOutlineCode = 2;
  // The raster G-buffer draws the disk as a polygon of this many sides
  // (inscribed: its edge is within radius x (1 - cos(pi / 96)) = 5.4e-4
  // radius of the circle); every other use is the exact disk.
  static constexpr int kOutlineSides = 96;
  Vec3 center{};
  Vec3 normal{0.0, -1.0, 0.0};  // unit
  double radius = 1.0;
  Vec3 t{1.0, 0.0, 0.0};  // derived: t, b, normal a right-handed frame
  Vec3 b{0.0, 0.0, -1.0};
  double area = 3.141592653589793;  // derived

  static DiskLight parse(const LightParse& in);
  // A disk with the derived frame and area (normal: any nonzero finite vector).
  static DiskLight make(const Vec3& center, const Vec3& normal, double radius);
  Aabb bounds() const;
  Emission emit(const LightRandom& u) const;
  LightSample sample(const Vec3& x, const LightRandom& u) const;
  std::optional<double> hit(const Vec3& o, const Vec3& v, double t_max) const;
  // The images of a k x k grid's cell centres under the concentric map of
  // the square onto the disk (equal areas), listed 2 x 2 cell by 2 x 2 cell
  // as the quad's, so every fourth point spans the whole disk.
  std::vector<DirectPoint> direct_points(int samples) const;
  double radiance_scale() const;
  std::optional<LightOutline> outline() const;
  void outline_triangles(TriangleSink& sink) const;
  void cache_key(LightKey& k) const;

 private:
  // The point of the disk at (x, y) in [0, 1)^2, uniform in area.
  Vec3 point(double x, double y) const;
};

}  // namespace beamcast
