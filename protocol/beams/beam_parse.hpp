// What a beam kind's parse function reads from: the beam's JSON object (the
// scene parser has already refused unknown keys and read the shared fields),
// the scene limits and the beam's radius. Included by the kinds' .cpp files.
#pragma once

#include "protocol/json_reader.hpp"
#include "protocol/scene_json.hpp"
#include "protocol/scene_readers.hpp"

namespace beamcast {

struct BeamParse {
  const json_read::ObjectReader& fields;
  const SceneLimits& limits;
  double radius;
};

}  // namespace beamcast
