// The light kinds, listed once: every use dispatches with std::visit over
// LightShape (docs/architecture.md, "Adding a scene element").
#pragma once

#include <string_view>
#include <variant>
#include <vector>

#include "protocol/lights/point.hpp"
#include "protocol/lights/quad.hpp"
#include "protocol/lights/spot.hpp"

namespace beamcast {

using LightShape = std::variant<PointLight, SpotLight, QuadLight>;

// The "type" strings of the kinds (hello's light_types).
std::vector<std::string_view> light_types();

}  // namespace beamcast
