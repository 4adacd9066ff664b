// Occluder "slim": a SLIM implicit surface (seed 003; issue 16), its support
// spheres inline ("spheres") or from a model file in the assets directory
// ("file": JSON or the binary form, protocol/slim_io.hpp), placed with
// "translate", "scale" (one number: a SLIM's quadratics stay quadratics
// only under uniform scaling) and "rotation". Drawn on the GPU by point
// sampling (pass "slim", render/slim_pass.cpp); the CPU reference ray casts
// the blended implicit function F (protocol/slim_model.hpp) in double.
#pragma once

#include <array>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "protocol/occluders/occluder_base.hpp"
#include "protocol/slim_model.hpp"

namespace beamcast {

// The spheres (world space) and the field over them; immutable once built,
// shared by every copy of the scene.
struct SlimSurface {
  explicit SlimSurface(std::vector<SlimSphere> s);
  SlimSurface(const SlimSurface&) = delete;
  SlimSurface& operator=(const SlimSurface&) = delete;

  const std::vector<SlimSphere> spheres;
  const Aabb box;
  const SlimField field;  // points into `spheres`

  // Each sphere's slim_height_range: computed on first use (the GPU's patch
  // evaluation; 66 ms for a 19 187-sphere model on this machine, which a
  // scene parse or a CPU render should not pay), then kept by the surface,
  // which every copy of the scene shares. Thread-safe.
  const std::vector<std::array<double, 2>>& height_ranges() const;
  // Names the spheres' values (their count, a 64-bit hash of all their
  // values and one of the second half): the renderer's cache key (render/slim_pass.hpp).
  // Computed on first use and kept, like height_ranges(). Thread-safe.
  const std::string& content_key() const;

 private:
  mutable std::once_flag ranges_once_;
  mutable std::vector<std::array<double, 2>> ranges_;
  mutable std::once_flag key_once_;
  mutable std::string key_;
};

struct SlimOccluder {
  static constexpr std::string_view kType = "slim";
  static constexpr GpuForm kGpu = GpuForm::kPoints;
  std::string file;  // as named in the scene; empty for inline spheres
  std::shared_ptr<const SlimSurface> surface;

  static SlimOccluder parse(const OccluderParse& in);
  // World-space spheres made by code (tests, benches).
  static SlimOccluder from_spheres(std::vector<SlimSphere> spheres);
  const std::vector<SlimSphere>& spheres() const { return surface->spheres; }
  Aabb bounds() const { return surface->box; }
  std::optional<OccluderHit> intersect(const Vec3& o, const Vec3& v, double t_min,
                                       double t_max) const;
};

struct Scene;
// True if the scene has a slim occluder (the slim passes run).
bool has_slim(const Scene& scene);

}  // namespace beamcast
