// What mirror and glass surfaces show in a lit scene (issue 14, item 4):
// the pass "specular". The G-buffer marks their pixels (material 1 or 2);
// for each, the CPU follows gi.specular_samples^2 rays spread over the
// pixel through the specular
// surfaces to what it reaches (gi/photon_gather.hpp, LitShading: the photon
// estimate and the direct light on diffuse surfaces, lights, background),
// and the pass adds that radiance to hdr. The photons' kd-trees come with
// the cached photon maps; the ray tracing scene (Embree) is built per
// request (group "specular").
#pragma once

#include <memory>

#include "render/pass_plan.hpp"

namespace beamcast {

class Pass;

std::unique_ptr<Pass> make_specular_pass();

}  // namespace beamcast
