// The beam kinds, listed once. The scene parser, hello's capabilities, camera
// rigs' bounds, the GPU path (render/scene_resources.cpp) and the CPU
// reference (render/reference.cpp) all visit this list; adding a kind is its
// own files plus its include and its name in BeamShape below (and, for a kind
// the beam shader cannot draw as a capsule record, shader code).
#pragma once

#include <string_view>
#include <variant>
#include <vector>

#include "protocol/beams/capsule.hpp"
#include "protocol/beams/sphere.hpp"

namespace beamcast {

using BeamShape = std::variant<SphereBeam, CapsuleBeam>;

// The "type" strings of every kind, in BeamShape's order.
std::vector<std::string_view> beam_types();

}  // namespace beamcast
