// What a light kind's parse function reads from: the light's JSON object and
// the scene limits. Included by the kinds' .cpp files only.
#pragma once

#include "protocol/json_reader.hpp"
#include "protocol/scene_json.hpp"
#include "protocol/scene_readers.hpp"

namespace beamcast {

struct LightParse {
  const json_read::ObjectReader& fields;
  const SceneLimits& limits;
};

}  // namespace beamcast
