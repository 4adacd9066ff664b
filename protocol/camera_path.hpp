// Camera paths: keyframed poses interpolated to N frames, for animations
// rendered by batch jobs (`beamcast render --path FILE --frames N`). Pure.
//
// File format (JSON):
//   {"interpolation": "catmull_rom" | "linear",   (default catmull_rom)
//    "frames": 120,                               (default: one per keyframe)
//    "camera": {...},   fields of a camera except the pose: projection, fov_y,
//                       ortho_height, near, far, width, height (default: the
//                       scene's first camera's)
//    "keyframes": [{"time": 0, "position": [x,y,z], "target": [x,y,z],
//                   "up": [0,1,0]}, ...]}          (2 or more; time optional,
//                                                   default the index, increasing)
// Frame i of N samples time t0 + (t_last - t0) * i / (N - 1). Positions and
// targets are interpolated by the same rule (linear, or uniform Catmull-Rom
// per keyframe segment with the end keyframes repeated, which passes through
// every keyframe); the camera looks at the interpolated target with the
// linearly interpolated up. Errors carry JSON paths into the file.
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "protocol/scene.hpp"
#include "protocol/scene_json.hpp"

namespace beamcast {

struct CameraKeyframe {
  double time = 0.0;
  Vec3 position{};
  Vec3 target{};
  Vec3 up{0.0, 1.0, 0.0};
};

struct CameraPath {
  enum class Interpolation { kLinear, kCatmullRom };
  Interpolation interpolation = Interpolation::kCatmullRom;
  int frames = 0;  // 0: one per keyframe
  std::vector<CameraKeyframe> keyframes;
  Camera base;  // intrinsics
};

// Parses and validates a path file's JSON; `base` supplies the intrinsics the
// file leaves out. Throws ProtocolError.
CameraPath parse_camera_path(const nlohmann::json& j, const Camera& base, const SceneLimits& limits);

// The interpolated pose at time t (clamped to the keyframes' range).
CameraKeyframe sample_camera_path(const CameraPath& path, double t);

// `frames` cameras (0: path.frames, else one per keyframe), named frame_0000...
// Throws ProtocolError (invalid_value at /keyframes) if an interpolated pose
// is degenerate (target at the position, up along the view).
std::vector<Camera> expand_camera_path(const CameraPath& path, int frames = 0);

}  // namespace beamcast
