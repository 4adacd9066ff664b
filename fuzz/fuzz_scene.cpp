// libFuzzer target: a scene document (what `beamcast render` and scene.put
// read) through parse_scene, then a single camera through parse_camera and an
// output block through parse_output_settings. A scene that parses must satisfy
// the invariants the renderer relies on (finite values, sizes within limits).
#include <cmath>
#include <cstdint>
#include <string_view>

#include "fuzz/fuzz_support.hpp"
#include "protocol/bounded_json.hpp"
#include "protocol/request.hpp"
#include "protocol/scene_json.hpp"

using beamcast::ProtocolError;
using json = nlohmann::json;

namespace {

void check_scene(const beamcast::Scene& s, const beamcast::SceneLimits& l) {
  FUZZ_CHECK(static_cast<int>(s.beams.size()) <= l.max_beams);
  FUZZ_CHECK(static_cast<int>(s.occluders.size()) <= l.max_occluders);
  FUZZ_CHECK(!s.cameras.empty() && static_cast<int>(s.cameras.size()) <= l.max_cameras);
  for (const beamcast::Camera& c : s.cameras) {
    FUZZ_CHECK(c.width >= 1 && c.width <= l.max_width && c.height >= 1 && c.height <= l.max_height);
    FUZZ_CHECK(static_cast<std::int64_t>(c.width) * c.height <= l.max_pixels);
    for (double v : c.position) FUZZ_CHECK(std::isfinite(v));
  }
  for (const beamcast::Beam& b : s.beams) {
    FUZZ_CHECK(std::isfinite(b.radius) && b.radius > 0.0);
  }
  // Volumes: what the ray caster and the GPU packing index and divide by.
  FUZZ_CHECK(static_cast<int>(s.volumes.size()) <= beamcast::kMaxVolumes);
  std::int64_t voxels = 0;
  for (const beamcast::Volume& v : s.volumes) {
    FUZZ_CHECK(v.grid != nullptr);
    for (int n : v.grid->dims) FUZZ_CHECK(n >= 2 && n <= beamcast::kMaxVolumeDimension);
    FUZZ_CHECK(static_cast<std::int64_t>(v.grid->values.size()) == v.grid->voxels());
    voxels += v.grid->voxels();
    for (int a = 0; a < 3; ++a) FUZZ_CHECK(std::isfinite(v.spacing[a]) && v.spacing[a] > 0.0);
    FUZZ_CHECK(v.range[0] < v.range[1] && std::isfinite(v.range[1] - v.range[0]));
    FUZZ_CHECK(v.transfer.points.size() >= 2 && v.transfer.opacity_unit > 0.0);
    for (std::size_t i = 1; i < v.transfer.points.size(); ++i) {
      FUZZ_CHECK(v.transfer.points[i].value > v.transfer.points[i - 1].value);
    }
  }
  FUZZ_CHECK(voxels <= beamcast::kMaxVolumeVoxels);
  FUZZ_CHECK(s.volume.level >= 0 && s.volume.level <= beamcast::kMaxVolumeLevel);
  FUZZ_CHECK(s.volume.samples_per_voxel > 0.0 && s.volume.samples_per_voxel <= 64.0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const beamcast::SceneLoadOptions opts = beamcast::fuzz::load_options();
  // Scenes arrive inside requests: the same bounded parser and limits.
  beamcast::BoundedParse parsed = beamcast::parse_json_bounded(text, beamcast::JsonLimits{});
  if (parsed.error) {
    beamcast::fuzz::check_error(*parsed.error);
    beamcast::fuzz::serialize(beamcast::error_response(1, *parsed.error));
    return 0;
  }
  const json& j = parsed.value;
  FUZZ_CHECK(beamcast::json_depth(j) <= beamcast::JsonLimits{}.max_depth);
  json response;
  try {
    const beamcast::Scene scene = beamcast::parse_scene(j, opts);
    check_scene(scene, opts.limits);
    response = {{"beams", scene.beams.size()}};
  } catch (const ProtocolError& e) {
    beamcast::fuzz::check_error(e.info());
    response = beamcast::error_response(1, e.info());
  }
  beamcast::fuzz::serialize(response);
  // The same document read as one camera (render's params.cameras[i]) and as an output block.
  try {
    const beamcast::Camera c = beamcast::parse_camera(j, "/params/cameras/0", opts.limits);
    FUZZ_CHECK(c.width >= 1 && c.height >= 1);
  } catch (const ProtocolError& e) {
    beamcast::fuzz::check_error(e.info());
    beamcast::fuzz::serialize(beamcast::error_response(1, e.info()));
  }
  try {
    (void)beamcast::parse_output_settings(j, "/params/output");
  } catch (const ProtocolError& e) {
    beamcast::fuzz::check_error(e.info());
    beamcast::fuzz::serialize(beamcast::error_response(1, e.info()));
  }
  return 0;
}
