// Camera rigs: orbit, cube map and stereo pair, expanded to explicit cameras.
// Pure math on validated values (scene_json.cpp reads and checks the JSON, with
// paths); docs/scene-format.md#camera-rigs documents the layouts.
#pragma once

#include <string>
#include <vector>

#include "protocol/scene.hpp"

namespace beamcast {

// `count` cameras looking at `target` from `radius` away. Circle: evenly spaced
// around `axis` at `elevation_deg` above the plane through the target normal to
// the axis, the first at `start_deg`. Sphere: a Fibonacci lattice over the
// sphere (even coverage, poles excluded). Angle 0 is the direction of world +Z
// projected onto the plane (+X if the axis is along Z); angles grow right-handed
// about the axis. Every camera's up is the axis.
struct OrbitRig {
  enum class Layout { kCircle, kSphere };
  Layout layout = Layout::kCircle;
  int count = 8;
  Vec3 target{0.0, 0.0, 0.0};
  double radius = 5.0;
  Vec3 axis{0.0, 1.0, 0.0};  // unit
  double elevation_deg = 0.0;  // circle only, in (-90, 90)
  double start_deg = 0.0;
};

// Six 90-degree square views from `position`, in the order of kCubemapFaces.
struct CubemapRig {
  Vec3 position{0.0, 0.0, 0.0};
};

// Face names, view directions and image-up directions, in output order.
struct CubemapFace {
  const char* name;
  Vec3 forward;
  Vec3 up;
};
extern const CubemapFace kCubemapFaces[6];

// Left and right eyes `separation` apart along the centre camera's right
// vector, both turned in to look at the point `convergence` ahead of the centre
// (toe-in), with the centre camera's up.
struct StereoRig {
  Vec3 position{0.0, 0.0, 5.0};
  Vec3 target{0.0, 0.0, 0.0};
  Vec3 up{0.0, 1.0, 0.0};
  double separation = 0.065;
  double convergence = 0.0;  // <= 0: |target - position|
};

// Each expansion copies `base` (projection, fov, planes, size) and sets the
// pose, and names the cameras `prefix` + "_" + suffix (orbit: 000, 001, ...;
// cube map: px, nx, py, ny, pz, nz; stereo: left, right).
std::vector<Camera> expand_orbit(const OrbitRig& rig, const Camera& base, const std::string& prefix);
std::vector<Camera> expand_cubemap(const CubemapRig& rig, const Camera& base,
                                   const std::string& prefix);
std::vector<Camera> expand_stereo(const StereoRig& rig, const Camera& base,
                                  const std::string& prefix);

}  // namespace beamcast

namespace beamcast {

// A rig from a command-line spec, framed by the scene's first camera, for
// turntables and batch jobs (`beamcast render --rig`):
//   "orbit:K"   K cameras on the circle through the first camera's position
//               around the centre of the beams' bounding box (the first camera's
//               target if there are no beams), axis = the first camera's up;
//               camera 0 is at the first camera's position
//   "cubemap[:SIZE]"  the six faces at the first camera's position (SIZE: its width)
//   "stereo[:SEPARATION]"  a pair around the first camera, converging on its
//               target (or the beams' centre); SEPARATION default: distance / 30
// Cameras copy the first camera's projection, fov, planes and size. Throws
// ProtocolError (invalid_value) naming the spec.
std::vector<Camera> rig_from_spec(const std::string& spec, const Scene& scene);

}  // namespace beamcast
