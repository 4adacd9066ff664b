// What mirror and glass surfaces show in a lit scene (issue 14, item 4):
// the pass "specular". The G-buffer marks their pixels (material 1 or 2);
// for each, gi.specular_samples^2 rays spread over the pixel are followed
// through the specular surfaces to what they reach (gi/photon_gather.hpp,
// LitShading: the photon estimate and the direct light on diffuse
// surfaces, lights, background), and the pass adds that radiance to hdr.
// By default (gi.specular_tracer "gpu") a compute pass traces them
// (shaders/specular_trace.comp, over buffers of render/specular_gpu.hpp,
// issue 39 item 4); with "cpu", or for a scene the GPU tracer does not
// cover (gpu_traces_specular), the CPU does, with Embree built per request
// and the photons' kd-trees kept with the cached photon maps (group
// "specular" uploads one or the other).
#pragma once

#include <memory>

#include "render/pass_plan.hpp"

namespace beamcast {

class Pass;

std::unique_ptr<Pass> make_specular_pass();

}  // namespace beamcast
