// Shared helpers of the fuzz targets: checks that trap (a libFuzzer finding),
// the scene-load options the server uses, and response serialization exactly
// as the server does it (strict UTF-8: a throw here is a server crash).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "protocol/errors.hpp"
#include "protocol/scene_json.hpp"

#define FUZZ_CHECK(cond) \
  do {                   \
    if (!(cond)) {       \
      __builtin_trap();  \
    }                    \
  } while (0)

namespace beamcast::fuzz {

// The server's defaults (server/config.hpp), no assets directory: mesh
// occluders are refused by path, the OBJ parser has its own target.
inline SceneLoadOptions load_options() {
  SceneLoadOptions o;
  o.limits = kServerSceneLimits;
  return o;
}

// A small valid scene: the stored scene that scene.update patches and the
// scene a render by scene_id would use.
inline const nlohmann::json& base_scene_json() {
  static const nlohmann::json j = nlohmann::json::parse(R"({
    "beams": [{"type": "capsule", "p0": [0, 0, 0], "p1": [0, 1, 0], "radius": 0.2,
               "density": "abe", "color": [1, 0.5, 0.2], "intensity": 1}],
    "cameras": [{"position": [0, 0.5, 3], "target": [0, 0.5, 0], "fov_y": 45,
                 "width": 8, "height": 8}]
  })");
  return j;
}

// Every error has a code and a message; the path is empty or a JSON pointer.
inline void check_error(const ErrorInfo& e) {
  FUZZ_CHECK(!e.code.empty());
  FUZZ_CHECK(!e.message.empty());
  FUZZ_CHECK(e.path.empty() || e.path[0] == '/');
}

inline void serialize(const nlohmann::json& j) {
  try {
    (void)j.dump();
  } catch (const nlohmann::json::exception&) {
    __builtin_trap();  // the server's Session::send would throw here
  }
}

}  // namespace beamcast::fuzz
