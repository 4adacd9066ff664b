// The extent of a scene's lit geometry, for defaults that scale with it
// (photon kernel radii, the preview's photon LOD).
#pragma once

#include "protocol/scene.hpp"

namespace beamcast {

// The bounds of the finite occluders (planes left out) and the lights;
// empty when there are none.
Aabb scene_box(const Scene& scene);

}  // namespace beamcast
