#include "protocol/lights/lights.hpp"

#include "protocol/kinds.hpp"

namespace beamcast {

std::vector<std::string_view> light_types() { return kind_types<LightShape>(); }

}  // namespace beamcast
