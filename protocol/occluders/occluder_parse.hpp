// What an occluder kind's parse function reads from: the occluder's JSON
// object, the load options (limits, assets directory) and the scene's running
// mesh triangle and SLIM sphere counts. Included by the kinds' .cpp files only.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string_view>

#include "protocol/json_reader.hpp"
#include "protocol/scene_json.hpp"
#include "protocol/scene_readers.hpp"

namespace beamcast {

struct OccluderParse {
  const json_read::ObjectReader& fields;
  const SceneLoadOptions& opts;
  std::int64_t* mesh_triangles;  // triangles of the scene's meshes so far
  std::int64_t* slim_spheres;    // support spheres of the scene's SLIM surfaces so far

  const SceneLimits& limits() const { return opts.limits; }
  // Refuses keys other than the kind's `fields`, "type" and "albedo" (read by
  // the scene parser for every kind).
  void allow(std::initializer_list<std::string_view> kind_fields) const;
};

}  // namespace beamcast
