#include "protocol/rigs.hpp"

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>
#include <limits>
#include <variant>

#include "protocol/camera.hpp"
#include "protocol/errors.hpp"

namespace beamcast {

namespace {

constexpr double kPi = 3.14159265358979323846;

Camera posed(const Camera& base, const std::string& name, const Vec3& position, const Vec3& target,
             const Vec3& up) {
  Camera c = base;
  c.name = name;
  c.position = position;
  c.target = target;
  c.rotation.reset();
  c.up = up;
  return c;
}

}  // namespace

const CubemapFace kCubemapFaces[6] = {
    {"px", {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}},  {"nx", {-1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}},
    {"py", {0.0, 1.0, 0.0}, {0.0, 0.0, -1.0}}, {"ny", {0.0, -1.0, 0.0}, {0.0, 0.0, 1.0}},
    {"pz", {0.0, 0.0, 1.0}, {0.0, 1.0, 0.0}},  {"nz", {0.0, 0.0, -1.0}, {0.0, 1.0, 0.0}},
};

std::vector<Camera> expand_orbit(const OrbitRig& rig, const Camera& base,
                                 const std::string& prefix) {
  const Vec3 axis = normalize(rig.axis);
  // Angle 0: world +Z projected onto the orbit plane (+X when the axis is along Z).
  Vec3 ref{0.0, 0.0, 1.0};
  if (length(cross(axis, ref)) < 1e-6) ref = {1.0, 0.0, 0.0};
  const Vec3 e1 = normalize(ref - dot(ref, axis) * axis);
  const Vec3 e2 = cross(axis, e1);  // e1 turned +90 degrees about the axis
  std::vector<Camera> cams;
  cams.reserve(static_cast<std::size_t>(rig.count));
  for (int i = 0; i < rig.count; ++i) {
    double along = 0.0, angle = 0.0;  // sin(elevation), azimuth in radians
    if (rig.layout == OrbitRig::Layout::kCircle) {
      along = std::sin(rig.elevation_deg * kPi / 180.0);
      angle = (rig.start_deg + 360.0 * i / rig.count) * kPi / 180.0;
    } else {
      // Fibonacci lattice: equal-area bands in `along`, golden-angle azimuths.
      along = 1.0 - (2.0 * i + 1.0) / rig.count;
      angle = rig.start_deg * kPi / 180.0 + i * kPi * (3.0 - std::sqrt(5.0));
    }
    const double across = std::sqrt(std::max(0.0, 1.0 - along * along));
    const Vec3 dir = across * std::cos(angle) * e1 + across * std::sin(angle) * e2 + along * axis;
    char suffix[16];
    std::snprintf(suffix, sizeof suffix, "_%03d", i);
    cams.push_back(posed(base, prefix + suffix, rig.target + rig.radius * dir, rig.target, axis));
  }
  return cams;
}

std::vector<Camera> expand_cubemap(const CubemapRig& rig, const Camera& base,
                                   const std::string& prefix) {
  std::vector<Camera> cams;
  for (const CubemapFace& face : kCubemapFaces) {
    Camera c = posed(base, prefix + "_" + face.name, rig.position, rig.position + face.forward,
                     face.up);
    c.projection = Projection::kPerspective;
    c.fov_y_deg = 90.0;
    c.height = c.width;
    cams.push_back(c);
  }
  return cams;
}

std::vector<Camera> expand_stereo(const StereoRig& rig, const Camera& base,
                                  const std::string& prefix) {
  const Vec3 to_target = rig.target - rig.position;
  const Vec3 forward = normalize(to_target);
  const Vec3 right = normalize(cross(forward, rig.up));
  const double convergence = rig.convergence > 0.0 ? rig.convergence : length(to_target);
  const Vec3 focus = rig.position + convergence * forward;
  const Vec3 half = (0.5 * rig.separation) * right;
  return {posed(base, prefix + "_left", rig.position - half, focus, rig.up),
          posed(base, prefix + "_right", rig.position + half, focus, rig.up)};
}

namespace {

[[noreturn]] void bad_spec(const std::string& spec, const std::string& why) {
  throw ProtocolError(ErrorInfo{"invalid_value", "rig \"" + spec + "\": " + why, ""});
}

// Centre of the beams' bounding box (spheres: centres; capsules: both ends).
std::optional<Vec3> beams_centre(const Scene& scene) {
  if (scene.beams.empty()) return std::nullopt;
  Aabb box;
  for (const Beam& b : scene.beams) {
    box.grow(std::visit([](const auto& shape) { return shape.defining_bounds(); }, b.shape));
  }
  return box.centre();
}

// The integer after "name:" (or `fallback` without one).
double spec_number(const std::string& spec, std::size_t colon, double fallback) {
  if (colon == std::string::npos) return fallback;
  const std::string text = spec.substr(colon + 1);
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || text.empty() || !std::isfinite(v) || v <= 0.0) {
    bad_spec(spec, "\"" + text + "\" is not a positive number");
  }
  return v;
}

}  // namespace

std::vector<Camera> rig_from_spec(const std::string& spec, const Scene& scene) {
  if (scene.cameras.empty()) bad_spec(spec, "the scene has no camera to frame the rig");
  const Camera& first = scene.cameras.front();
  const CameraBasis basis = camera_basis(first);
  const std::size_t colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const Vec3 centre =
      first.target ? beams_centre(scene).value_or(*first.target)
                   : beams_centre(scene).value_or(first.position + 5.0 * basis.forward);
  if (kind == "orbit") {
    const double count = spec_number(spec, colon, 36.0);
    if (count != std::floor(count) || count > 4096) {
      bad_spec(spec, "the count must be an integer from 1 to 4096");
    }
    OrbitRig rig;
    rig.count = static_cast<int>(count);
    rig.target = centre;
    rig.axis = basis.up;
    const Vec3 offset = first.position - centre;
    rig.radius = length(offset);
    if (!(rig.radius > 0.0)) bad_spec(spec, "the first camera sits at the orbit's centre");
    const double along = dot(offset, rig.axis) / rig.radius;
    rig.elevation_deg = std::asin(std::clamp(along, -1.0, 1.0)) * 180.0 / kPi;
    if (std::abs(rig.elevation_deg) > 89.0) {
      bad_spec(spec, "the first camera is above or below the centre, on the orbit's axis");
    }
    // Azimuth of the first camera in the orbit's frame (see expand_orbit).
    Vec3 ref{0.0, 0.0, 1.0};
    if (length(cross(rig.axis, ref)) < 1e-6) ref = {1.0, 0.0, 0.0};
    const Vec3 e1 = normalize(ref - dot(ref, rig.axis) * rig.axis);
    const Vec3 e2 = cross(rig.axis, e1);
    rig.start_deg = std::atan2(dot(offset, e2), dot(offset, e1)) * 180.0 / kPi;
    return expand_orbit(rig, first, "orbit");
  }
  if (kind == "cubemap") {
    Camera base = first;
    const double size = spec_number(spec, colon, first.width);
    if (size != std::floor(size) || size > 8192) bad_spec(spec, "the size must be 1 to 8192");
    base.width = static_cast<int>(size);
    return expand_cubemap(CubemapRig{first.position}, base, "cubemap");
  }
  if (kind == "stereo") {
    StereoRig rig;
    rig.position = first.position;
    rig.target = first.target.value_or(centre);
    rig.up = basis.up;
    const double distance = length(rig.target - first.position);
    if (!(distance > 0.0)) bad_spec(spec, "the first camera sits at the scene's centre");
    rig.separation = spec_number(spec, colon, distance / 30.0);
    return expand_stereo(rig, first, "stereo");
  }
  bad_spec(spec, "the rig must be orbit[:COUNT], cubemap[:SIZE] or stereo[:SEPARATION]");
}

}  // namespace beamcast
