// Shared by the volume unit tests (test_volume.cpp, test_volume_files.cpp):
// a scene around one volume and the error a scene is refused with.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "protocol/errors.hpp"
#include "protocol/scene_json.hpp"

namespace beamcast::test {

inline nlohmann::json volume_scene(nlohmann::json volume) {
  return {{"volumes", nlohmann::json::array({std::move(volume)})},
          {"cameras", {{{"position", {0, 0, 5}}, {"target", {0, 0, 0}}}}}};
}

inline ErrorInfo volume_error(const nlohmann::json& j, const SceneLoadOptions& opts = {}) {
  try {
    parse_scene(j, opts);
  } catch (const ProtocolError& e) {
    return e.info();
  }
  ADD_FAILURE() << "scene was accepted: " << j.dump().substr(0, 400);
  return {};
}

#define EXPECT_VOLUME_ERROR(scene, opts, want_code, want_path)                    \
  do {                                                                            \
    const ::beamcast::ErrorInfo e_ = ::beamcast::test::volume_error(scene, opts); \
    EXPECT_EQ(e_.code, want_code) << e_.message;                                  \
    EXPECT_EQ(e_.path, want_path) << e_.message;                                  \
  } while (0)

}  // namespace beamcast::test
