// The accuracy controller of `quality: "auto"` renders (issue 7): per client,
// picks the most accurate rendering that fits a frame-time budget while the
// camera moves, changes it at most one step per frame, and asks for a
// full-accuracy frame once the camera has been still long enough.
//
// Pure: no GL, no sockets, no clock of its own (callers pass the time), so it
// is unit-tested directly (tests/unit/test_accuracy_controller.cpp).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "protocol/scene.hpp"

namespace beamcast {

// Photon level of detail for a level (GiSettings::lod_*, seed 001 section
// 6); 0 groups: none.
struct PhotonLod {
  int groups = 0;
  double near = 0.0;
  double far = 0.0;
};

// One rung of the ladder: how a frame is rendered.
struct AccuracyLevel {
  std::string label;      // e.g. "full", "table32", "table32@1/2"
  double scale = 1.0;     // resolution scale: render smaller, upscale bilinearly on the GPU
  RenderSettings render;  // integration settings
  // Interactive JPEG frames are encoded at this quality. A connection that
  // streams video (render param "video", server/video_stream.hpp) ignores it:
  // its encoder's rate control holds the bitrate target at every level.
  int jpeg_quality = 90;
  // Lit scenes: the share of the cached photon maps splatted
  // (GiSettings::display_fraction; nothing is traced again).
  double photon_fraction = 1.0;
  // Lit scenes: the photon LOD of this level (replaces the scene's gi.lod).
  PhotonLod lod;
  // Scenes with volumes: the ray caster's settings of this level (replace
  // the scene's "volume"); none: the scene's own.
  std::optional<VolumeSettings> volume;
};

// The ladder for a scene whose full-accuracy settings are `full`, ordered from
// most accurate (index 0: exactly `full` at scale 1) to cheapest. A lit scene
// (`lit`: photon splatting, the frame's largest cost) also splats a quarter
// of its cached photons (at 4x their power and the default radius of that
// count) on every level below the full one: 4x fewer splats for about 2x
// the photon noise (docs/gi.md, "Preview").
// With `lod` (groups > 0) a lit scene's ladder ends with one level more:
// the cheapest one thinned by that LOD as well (docs/media.md, "LOD in the
// preview": there LOD costs more error than a resolution step at equal
// time, so it comes last).
inline constexpr double kPreviewPhotonFraction = 0.25;
std::vector<AccuracyLevel> make_accuracy_ladder(const RenderSettings& full, bool lit = false,
                                                const PhotonLod& lod = {});

// The LOD a lit scene's preview uses while the camera moves: none when the
// scene sets its own gi.lod (it applies to every frame already); else the
// seed's near-photons-dropped form (near > far: Q = 1 - smoothstep(far,
// near, d)) over the scene's size `scene_size` (its bounds' diagonal):
// near = scene_size, far = 0, 16 groups, so a photon at distance d from
// the eye survives with probability about smoothstep(0, scene_size, d) and
// carries 1 / that of its power; the nearest photons, whose splats cover
// the most pixels, go first (seed fig 6.1: about 2x frames/s).
PhotonLod preview_lod(const GiSettings& gi, double scene_size);

// The ladder of a scene with volumes (seed 004's policy: one knob a step,
// full accuracy at rest): from `vol` (the scene's settings) to S_z 1 with
// ERT 0.98, then resolution 3/4 and 1/2, then S_z 1/2, then R_v one level
// down, then resolution 1/4. Opacity correction stays on (the scene's
// choice), so the brightness holds from level to level (docs/volumes.md
// measures each level's time, error and mean).
std::vector<AccuracyLevel> make_volume_ladder(const RenderSettings& full, const VolumeSettings& vol);

// make_accuracy_ladder for a scene: lit or not, with preview_lod over the
// diagonal of its bounds (protocol/scene_bounds.hpp); make_volume_ladder
// for a scene with volumes.
std::vector<AccuracyLevel> preview_ladder(const Scene& scene);

// The scene as `level` renders it: its integration settings, the share of
// photons drawn and, where the level has one, its photon LOD (the
// resolution scale is the frame's, FrameOptions::resolution_scale).
void apply_accuracy_level(const AccuracyLevel& level, Scene* scene);

struct ControllerConfig {
  double budget_ms = 33.0;  // frame-time budget while the camera moves
  double still_ms = 300.0;  // still this long -> one full-accuracy frame
  double ewma_alpha = 0.3;  // weight of the newest observed frame time
  // Climb to a more accurate level only if its estimate is below this share of
  // the budget, so measurement noise does not flip between two levels.
  double climb_margin = 0.85;
  // A level's own measurement older than this is replaced by a prediction from
  // the freshest level (load on a shared machine changes).
  double stale_ms = 2000.0;
};

enum class Motion { kInfer, kMoving, kStill };

// A camera pose, compared exactly: any change counts as motion.
using PoseKey = std::vector<double>;
PoseKey pose_key(const std::vector<Camera>& cameras);

struct ControllerDecision {
  int level = 0;
  bool still = false;   // the full-accuracy still frame (PNG, pixel-exact)
  std::string reason;   // still | moving | over_budget | under_budget | settling | first_frame
  bool moving = false;  // motion as seen (given or inferred)
  double estimate_ms = 0.0;  // predicted frame time of the chosen level (0 if unknown)
};

class AccuracyController {
 public:
  AccuracyController(std::vector<AccuracyLevel> ladder, ControllerConfig config);

  // Decides the next frame at time `now_ms` (any monotonic clock, in ms) for
  // the camera pose `pose`; with Motion::kInfer motion is a pose change since
  // the previous frame.
  ControllerDecision decide(double now_ms, const PoseKey& pose, Motion motion);
  // Reports the measured cost of a frame rendered at `level`: render with
  // read-back plus the frame's encode (JPEG, or the video encoder's, which
  // works at the output size whatever the level and so lands in the fit's
  // fixed part), so the budget covers the encoder.
  void observe(int level, double frame_ms, double now_ms);

  // Predicted frame time of `level` at `now_ms`: its own recent measurement,
  // else a fit of fixed + per-pixel cost to the freshest measurements (the
  // first full frame and the first scaled one are the calibration); nullopt
  // before any measurement.
  std::optional<double> estimate(int level, double now_ms) const;
  const std::vector<AccuracyLevel>& ladder() const { return ladder_; }
  const ControllerConfig& config() const { return config_; }
  void set_budget(double budget_ms) { config_.budget_ms = budget_ms; }
  void set_still_ms(double still_ms) { config_.still_ms = still_ms; }
  int interactive_level() const { return level_; }

 private:
  struct Cost {
    double ewma_ms = 0.0;
    double last_ms = -1.0;  // time of the last observation; < 0: never
  };
  double pixels(int level) const;

  std::vector<AccuracyLevel> ladder_;
  ControllerConfig config_;
  std::vector<Cost> costs_;
  int level_ = -1;  // interactive level; -1 until the first moving frame
  std::optional<PoseKey> last_pose_;
  double last_motion_ms_ = 0.0;
  bool ever_moved_ = false;
};

}  // namespace beamcast
