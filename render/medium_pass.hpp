// A participating medium filling the scene (issue 15; docs/media.md): the
// pass "medium" attenuates what the surfaces and the background send to the
// eye by e^(-sigma_t s) (s the ray distance to the surface), before the
// beams, which attenuate their own light along the ray and within
// themselves (shaders/beam_math.glsl, medium_piece); and the pass
// "volume_photons" adds the light the medium scatters towards the eye.
#pragma once

#include <memory>

namespace beamcast {

class Pass;

std::unique_ptr<Pass> make_medium_pass();
// The pass "volume_photons": the light the medium scatters towards the eye,
// from the volume photon map (seed 001, chapter 5).
std::unique_ptr<Pass> make_volume_photon_pass();

}  // namespace beamcast
