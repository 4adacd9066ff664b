// An example scene of examples/ with its first camera only, at size x size
// (the GL tests' small frames).
#pragma once

#include <filesystem>
#include <string>

#include "protocol/scene_json.hpp"

namespace beamcast {

inline Scene small_example(const std::string& name, int size) {
  const auto dir = std::filesystem::path(BEAMCAST_SOURCE_DIR) / "examples";
  SceneLoadOptions opts;
  opts.assets_dir = dir;
  Scene s = load_scene_file(dir / (name + ".json"), opts);
  s.cameras.resize(1);
  s.cameras[0].width = s.cameras[0].height = size;
  return s;
}

}  // namespace beamcast
