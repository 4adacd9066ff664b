#include "protocol/beams/beams.hpp"

#include "protocol/kinds.hpp"

namespace beamcast {

std::vector<std::string_view> beam_types() { return kind_types<BeamShape>(); }

}  // namespace beamcast
