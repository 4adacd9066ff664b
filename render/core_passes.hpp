// Factories of the shared passes' executors (render/core_passes.cpp), for
// the rows of render/pass_catalog.cpp.
#pragma once

#include <memory>

#include "render/passes.hpp"

namespace beamcast {

// "surfaces" (false: shaded colour) or "gbuffer" (true: the G-buffer of a lit scene).
std::unique_ptr<Pass> make_surface_pass(bool gbuffer);
// "direct": all points into hdr (false), or interleaved lights' into direct_split (true).
std::unique_ptr<Pass> make_direct_pass(bool split);
std::unique_ptr<Pass> make_photon_pass();
std::unique_ptr<Pass> make_gi_resolve_pass();
std::unique_ptr<Pass> make_beam_pass();
std::unique_ptr<Pass> make_tonemap_pass();
std::unique_ptr<Pass> make_upscale_pass();

}  // namespace beamcast
