// The scene's surfaces and area lights for the CPU tracers of global
// illumination (photon tracing, the path-traced reference): Embree finds the
// nearest hit in float, and the hit is then recomputed in double on the
// element's own geometry (the occluder kind's intersect for planes and
// spheres, the triangle's plane for triangle kinds), so t, the point and the
// normal are double-precision. No GL.
#pragma once

#include <memory>
#include <optional>

#include "protocol/scene.hpp"

namespace beamcast {

struct SurfaceHit {
  double t = 0.0;
  Vec3 p{};
  Vec3 n{};              // unit geometric normal, facing the incoming ray
  bool entering = true;  // the ray hit the side the element's normal points to
  int occluder = -1;     // index in Scene::occluders, or -1
  int light = -1;        // index in Scene::lights (an emitter seen from its front), or -1
};

class GiScene {
 public:
  explicit GiScene(const Scene& scene);
  ~GiScene();
  GiScene(const GiScene&) = delete;
  GiScene& operator=(const GiScene&) = delete;

  // The nearest hit of o + t v (|v| = 1) with t in (t_min, t_max]; one-sided
  // triangles and quad lights are hit only from their front.
  std::optional<SurfaceHit> intersect(const Vec3& o, const Vec3& v, double t_min,
                                      double t_max) const;
  // Whether anything blocks o + t v for t in (t_min, t_max).
  bool occluded(const Vec3& o, const Vec3& v, double t_min, double t_max) const;
  // A distance that keeps a new ray off the surface it leaves: 1e-6 of the
  // scene's extent (the bounds of every occluder and light, planes excluded).
  double epsilon() const { return epsilon_; }
  const Scene& scene() const { return *scene_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  const Scene* scene_;
  double epsilon_ = 1e-6;
};

}  // namespace beamcast
