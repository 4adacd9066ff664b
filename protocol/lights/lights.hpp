// The light kinds, listed once: every use dispatches with std::visit over
// LightShape (docs/architecture.md, "Adding a scene element").
#pragma once

#include <string_view>
#include <variant>
#include <vector>

#include "protocol/lights/beam_emitter.hpp"
#include "protocol/lights/disk.hpp"
#include "protocol/lights/point.hpp"
#include "protocol/lights/quad.hpp"
#include "protocol/lights/spot.hpp"

namespace beamcast {

// BeamEmitter is derived (the light of a beam with "emit": true): never
// parsed from "lights", listed in no "type" list.
using LightShape = std::variant<PointLight, SpotLight, QuadLight, DiskLight, BeamEmitter>;

// The "type" strings of the kinds (hello's light_types).
std::vector<std::string_view> light_types();

}  // namespace beamcast
