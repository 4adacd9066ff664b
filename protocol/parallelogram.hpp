// The parallelogram corner + a edge_u + b edge_v (a, b in [0, 1]) shared by
// the quad occluder (protocol/occluders/quad) and the quad light
// (protocol/lights/quad): reading it, its bounds, and a ray's hit.
#pragma once

#include <optional>

#include "protocol/json_reader.hpp"
#include "protocol/scene_json.hpp"
#include "protocol/vec.hpp"

namespace beamcast {

struct Parallelogram {
  Vec3 corner{};
  Vec3 edge_u{1.0, 0.0, 0.0};
  Vec3 edge_v{0.0, 0.0, 1.0};

  // "corner", "edge_u", "edge_v" of `fields`; parallel edges (sin of the
  // angle between the unit edges below 1e-9: no normal, far from any
  // surface a scene means and far above double rounding), an edge shorter
  // than kMinLength or an area below kMinLength^2 are refused, naming
  // `what` ("quad", "light").
  static Parallelogram read(const json_read::ObjectReader& fields, const SceneLimits& limits,
                            const char* what);
  Vec3 normal_unnormalized() const { return cross(edge_u, edge_v); }
  double area() const { return length(normal_unnormalized()); }
  // Unit, towards cross(edge_u, edge_v).
  Vec3 unit_normal() const { return normalize(normal_unnormalized()); }
  Aabb bounds() const;
  // t of o + t v where it crosses the parallelogram, t in [t_min, t_max];
  // front_only: only against its normal cross(edge_u, edge_v).
  std::optional<double> hit(const Vec3& o, const Vec3& v, double t_min, double t_max,
                            bool front_only) const;
};

}  // namespace beamcast
