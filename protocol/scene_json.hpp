// JSON <-> scene model. Parsing validates everything a renderer relies on, so a
// Scene that comes out of here is safe to render; bad input throws ProtocolError
// with the JSON pointer of the offending field.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "protocol/errors.hpp"
#include "protocol/scene.hpp"

namespace beamcast {

// Named limits; a scene over any of them is rejected with code "limit_exceeded".
struct SceneLimits {
  int max_beams = 100000;
  int max_occluders = 10000;
  int max_cameras = 256;
  int max_width = 8192;
  int max_height = 8192;
  std::int64_t max_pixels = 8192LL * 8192LL;  // per camera
  std::int64_t max_mesh_triangles = 2000000;  // summed over the scene
  std::int64_t max_slim_spheres = 1000000;    // SLIM support spheres, summed over the scene
  int max_density_samples = 4096;
  int min_table = 8;
  int max_table = 1024;
  double max_abs_coordinate = 1e12;  // any position or size, world units
  int max_lights = 1024;
  std::int64_t max_photons = 20000000;  // gi.photons + gi.caustic_photons
  // Photon events (surface hits, medium scatterings) tracing may store, all
  // maps together: a photon stores up to gi.max_depth of them (52 bytes
  // each), so max_photons alone does not bound the maps' memory. Crossed
  // while tracing: the render fails with limit_exceeded (issue 43).
  std::int64_t max_photon_events = std::int64_t{1} << 26;
  // Depth texels of the direct-light pass's shadow maps: direct points
  // (one per point or spot light, about gi.direct_samples per quad light)
  // x 6 cube faces x gi.shadow_size^2; 4 bytes each.
  std::int64_t max_shadow_texels = 256LL << 20;
  // Voxels of a scene's volumes, summed (2 bytes each on the CPU and the GPU).
  std::int64_t max_volume_voxels = kMaxVolumeVoxels;
};

// The server's scene limits (PROTOCOL.md, "Limits"), stricter than the
// offline defaults above: beamcast-server's defaults and the fuzz targets'.
inline constexpr SceneLimits kServerSceneLimits{.max_beams = 10000,
                                                .max_occluders = 1000,
                                                .max_cameras = 64,
                                                .max_width = 4096,
                                                .max_height = 4096,
                                                .max_pixels = 4096LL * 4096LL,
                                                .max_mesh_triangles = 1000000,
                                                .max_slim_spheres = 200000,
                                                .max_lights = 64,
                                                .max_photons = 4000000,
                                                // 16 Mi events: 832 MiB at most.
                                                .max_photon_events = 16LL << 20,
                                                .max_shadow_texels = 32LL << 20,
                                                // 256^3: 32 MiB, built or read
                                                // in well under a second.
                                                .max_volume_voxels = 16LL << 20};

struct SceneLoadOptions {
  // Mesh files are read only from below this directory; absolute paths and
  // ".." components are refused. Empty: meshes are refused.
  std::filesystem::path assets_dir;
  SceneLimits limits;
};

// Throws ProtocolError.
Scene parse_scene(const nlohmann::json& j, const SceneLoadOptions& opts);
// Whether parse_scene(j) may read files below the assets directory: some
// object of the scene's arrays (occluders, media, volumes), or one of their
// members (a volume's source), has a "file" key. Looks no deeper, so it costs
// the arrays' lengths, not the scene's size (the server parses such scenes
// off its network threads).
bool scene_reads_files(const nlohmann::json& j);
// One camera object (used by requests that send only camera poses); `path` is
// the JSON pointer of `j` for error messages.
Camera parse_camera(const nlohmann::json& j, const std::string& path, const SceneLimits& limits);
// One entry of a "cameras" array: a camera, or a rig ({"rig": "orbit" | "cubemap" |
// "stereo", ...}) expanded to its cameras (docs/scene-format.md#camera-rigs).
std::vector<Camera> parse_camera_entry(const nlohmann::json& j, const std::string& path,
                                       const SceneLimits& limits);
// A whole "cameras" array at `path`: nonempty, rigs expanded, at most
// max_cameras after expansion, names unique.
std::vector<Camera> parse_camera_list(const nlohmann::json& j, const std::string& path,
                                      const SceneLimits& limits);
// The one check of a frame's size against max_width, max_height and
// max_pixels, for every frame the server renders or composes: cameras (also
// with default sizes), rig cameras, cube map faces, atlases. `width_path` and
// `height_path` name the fields that set the size, or the object whose default
// applied; `what` names the frame in the message ("camera", "atlas"). Throws
// limit_exceeded.
void check_frame_size(std::int64_t width, std::int64_t height, const SceneLimits& limits,
                      const std::string& width_path, const std::string& height_path,
                      std::string_view what);

// output.supersample: each camera's rendered size (its size times k) within
// the same limits, the error at `path`.
void check_supersampled_size(const std::vector<Camera>& cameras, int supersample,
                             const SceneLimits& limits, const std::string& path);

// The grid of an atlas of frames of these sizes (PROTOCOL.md, "Atlas";
// render/atlas.hpp composes it): columns = ceil(sqrt(K)), rows = ceil(K /
// columns), cells as large as the largest frame.
struct AtlasGrid {
  int columns = 0, rows = 0, cell_width = 0, cell_height = 0;
  std::int64_t width() const { return static_cast<std::int64_t>(columns) * cell_width; }
  std::int64_t height() const { return static_cast<std::int64_t>(rows) * cell_height; }
};
AtlasGrid atlas_grid(const std::vector<std::pair<int, int>>& sizes);

// A camera as scene JSON (parse_camera of the result gives the camera back;
// numbers are written with full double precision).
nlohmann::json camera_to_json(const Camera& c);
// An "output" object (exposure, tone, bit_depth, supersample); missing fields take defaults.
constexpr int kMaxSupersample = 4;
OutputSettings parse_output_settings(const nlohmann::json& j, const std::string& path);
// The scene element types this parser accepts, from the parser's own tables
// (hello's capabilities): beam_types, densities, occluder_types, camera_rigs.
nlohmann::json scene_capabilities();
// Reads and parses a scene file; JSON syntax errors become code "bad_json".
Scene load_scene_file(const std::filesystem::path& file, const SceneLoadOptions& opts);

}  // namespace beamcast
