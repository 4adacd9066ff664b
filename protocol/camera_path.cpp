#include "protocol/camera_path.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "protocol/camera.hpp"
#include "protocol/json_reader.hpp"

namespace beamcast {

using nlohmann::json;
using namespace json_read;

namespace {

// Uniform Catmull-Rom between p1 and p2 at u in [0, 1].
Vec3 catmull_rom(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3, double u) {
  const double u2 = u * u, u3 = u2 * u;
  Vec3 out{};
  for (int k = 0; k < 3; ++k) {
    out[k] = 0.5 * ((2.0 * p1[k]) + (-p0[k] + p2[k]) * u +
                    (2.0 * p0[k] - 5.0 * p1[k] + 4.0 * p2[k] - p3[k]) * u2 +
                    (-p0[k] + 3.0 * p1[k] - 3.0 * p2[k] + p3[k]) * u3);
  }
  return out;
}

Vec3 lerp(const Vec3& a, const Vec3& b, double u) { return a + u * (b - a); }

}  // namespace

CameraPath parse_camera_path(const json& j, const Camera& base, const SceneLimits& limits) {
  const Node root{&j, ""};
  ObjectReader o(root, "a camera path");
  o.allow_only({"interpolation", "frames", "camera", "keyframes"});
  CameraPath path;
  path.base = base;
  if (auto v = o.optional("interpolation")) {
    path.interpolation = read_enum<CameraPath::Interpolation>(
        *v, {{"linear", CameraPath::Interpolation::kLinear},
             {"catmull_rom", CameraPath::Interpolation::kCatmullRom}});
  }
  if (auto v = o.optional("frames")) {
    const std::int64_t n = read_integer(*v);
    if (n < 1 || n > 100000) {
      fail("out_of_range", v->path, "frames must be an integer in [1, 100000]");
    }
    path.frames = static_cast<int>(n);
  }
  if (auto v = o.optional("camera")) {
    ObjectReader c(*v, "a camera");
    c.allow_only({"projection", "fov_y", "ortho_height", "near", "far", "width", "height"});
    // Unset fields keep the base camera's values: parse the merge.
    json merged = {{"projection", base.projection == Projection::kOrthographic ? "orthographic"
                                                                               : "perspective"},
                   {"fov_y", base.fov_y_deg},
                   {"ortho_height", base.ortho_height},
                   {"near", base.near_plane},
                   {"far", base.far_plane},
                   {"width", base.width},
                   {"height", base.height}};
    merged.update(v->json());
    const Camera parsed = parse_camera(merged, v->path, limits);
    path.base.projection = parsed.projection;
    path.base.fov_y_deg = parsed.fov_y_deg;
    path.base.ortho_height = parsed.ortho_height;
    path.base.near_plane = parsed.near_plane;
    path.base.far_plane = parsed.far_plane;
    path.base.width = parsed.width;
    path.base.height = parsed.height;
  }
  const Node keys = o.required("keyframes");
  const auto items = read_array(keys, 100000, "keyframes");
  if (items.size() < 2) fail("invalid_value", keys.path, "a path needs at least 2 keyframes");
  for (std::size_t i = 0; i < items.size(); ++i) {
    ObjectReader k(items[i], "a keyframe");
    k.allow_only({"time", "position", "target", "up"});
    CameraKeyframe kf;
    kf.time = static_cast<double>(i);
    if (auto v = k.optional("time")) kf.time = read_number(*v);
    if (i > 0 && !(kf.time > path.keyframes.back().time)) {
      fail("invalid_value", k.path_of("time"),
           "keyframe times must increase, got " + format_number(kf.time) + " after " +
               format_number(path.keyframes.back().time));
    }
    const Node pos = k.required("position");
    kf.position = check_coordinates(pos, read_vec3(pos), limits.max_abs_coordinate);
    const Node target = k.required("target");
    kf.target = check_coordinates(target, read_vec3(target), limits.max_abs_coordinate);
    if (auto v = k.optional("up")) kf.up = read_vec3(*v);
    // The same look-at rules as a camera, with the same paths.
    json cam = {{"position", pos.json()}, {"target", target.json()}, {"up", kf.up}};
    parse_camera(cam, items[i].path, limits);
    path.keyframes.push_back(kf);
  }
  return path;
}

CameraKeyframe sample_camera_path(const CameraPath& path, double t) {
  const auto& k = path.keyframes;
  t = std::clamp(t, k.front().time, k.back().time);
  std::size_t i = 0;  // segment [k[i], k[i + 1]]
  while (i + 2 < k.size() && t > k[i + 1].time) ++i;
  const double u = (t - k[i].time) / (k[i + 1].time - k[i].time);
  CameraKeyframe out;
  out.time = t;
  out.up = lerp(k[i].up, k[i + 1].up, u);
  if (path.interpolation == CameraPath::Interpolation::kLinear) {
    out.position = lerp(k[i].position, k[i + 1].position, u);
    out.target = lerp(k[i].target, k[i + 1].target, u);
  } else {
    const std::size_t a = i == 0 ? 0 : i - 1, d = std::min(i + 2, k.size() - 1);
    out.position = catmull_rom(k[a].position, k[i].position, k[i + 1].position, k[d].position, u);
    out.target = catmull_rom(k[a].target, k[i].target, k[i + 1].target, k[d].target, u);
  }
  return out;
}

std::vector<Camera> expand_camera_path(const CameraPath& path, int frames) {
  const int n = frames > 0 ? frames : path.frames > 0 ? path.frames
                                                      : static_cast<int>(path.keyframes.size());
  const double t0 = path.keyframes.front().time, t1 = path.keyframes.back().time;
  std::vector<Camera> cams;
  cams.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double t = n == 1 ? t0 : t0 + (t1 - t0) * i / (n - 1);
    const CameraKeyframe kf = sample_camera_path(path, t);
    const Vec3 view = kf.target - kf.position;
    const double scale = std::max({1.0, length(kf.position), length(kf.target)});
    if (!(length(view) > 1e-12 * scale) || !(length(kf.up) > 0.0) ||
        length(cross(normalize(view), normalize(kf.up))) < 1e-6) {
      throw ProtocolError(ErrorInfo{
          "invalid_value",
          "frame " + std::to_string(i) + " (time " + format_number(t) +
              "): the interpolated target meets the position or the up vector is along the view",
          "/keyframes"});
    }
    Camera c = path.base;
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d", i);
    c.name = name;
    c.position = kf.position;
    c.target = kf.target;
    c.rotation.reset();
    c.up = kf.up;
    cams.push_back(c);
  }
  return cams;
}

}  // namespace beamcast
