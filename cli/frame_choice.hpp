// `render --camera NAME` and `--size WxH`: which of a scene's cameras to render
// and at what size, applied to a parsed scene (offline) or to the scene JSON
// (sent to a server).
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "protocol/scene.hpp"

namespace beamcast::cli {

struct FrameChoice {
  std::vector<std::string> cameras;  // names; empty: all
  int width = 0;                     // 0: each camera's own
  int height = 0;
  bool any() const { return !cameras.empty() || width > 0; }
};

// Registers --camera and --size on `cmd`.
void add_frame_choice_options(CLI::App* cmd, FrameChoice* choice);

// The scene's cameras cut to the chosen ones (in the order named) and sized;
// an unknown name throws ProtocolError (unknown_camera) naming the scene's.
void apply_frame_choice(const FrameChoice& choice, std::vector<Camera>* cameras);
// The same on a scene JSON's "cameras" array (entries without a "name" are
// camera_<index>, as frames are named).
void apply_frame_choice(const FrameChoice& choice, nlohmann::json* scene);

}  // namespace beamcast::cli
