#include "protocol/scene_bounds.hpp"

#include <cmath>
#include <variant>

namespace beamcast {

Aabb scene_box(const Scene& scene) {
  Aabb box;
  for (const Occluder& o : scene.occluders) {
    const Aabb b = std::visit([](const auto& k) { return k.bounds(); }, o.shape);
    if (std::isfinite(b.lo[0]) && std::isfinite(b.hi[0])) box.grow(b);
  }
  for (const Light& l : scene.lights) {
    box.grow(std::visit([](const auto& k) { return k.bounds(); }, l.shape));
  }
  return box;
}

}  // namespace beamcast
