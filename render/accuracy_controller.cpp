#include "render/accuracy_controller.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "protocol/scene_bounds.hpp"

namespace beamcast {
namespace {

bool same_settings(const RenderSettings& a, const RenderSettings& b) {
  return a.method == b.method && a.table_d == b.table_d && a.table_s == b.table_s &&
         a.layout == b.layout && a.filter == b.filter && a.f_table == b.f_table &&
         a.samples == b.samples && a.rule == b.rule && a.near_parallel == b.near_parallel;
}

std::string settings_label(const RenderSettings& r) {
  switch (r.method) {
    case IntegrationMethod::kClosedForm:
      return "closed_form";
    case IntegrationMethod::kMarch:
      return "march" + std::to_string(r.samples);
    case IntegrationMethod::kTable:
      break;
  }
  return "table" + std::to_string(r.table_d) + "x" + std::to_string(r.table_s);
}

}  // namespace

PhotonLod preview_lod(const GiSettings& gi, double scene_size) {
  if (gi.lod_groups > 0 || !(scene_size > 0.0) || !std::isfinite(scene_size)) return {};
  return {16, scene_size, 0.0};
}

std::vector<AccuracyLevel> preview_ladder(const Scene& scene) {
  if (!scene.volumes.empty()) return make_volume_ladder(scene.render, scene.volume);
  const Aabb box = scene_box(scene);
  const double size = box.empty() ? 0.0 : length(box.hi - box.lo);
  return make_accuracy_ladder(scene.render, scene.has_gi(), preview_lod(scene.gi, size));
}

void apply_accuracy_level(const AccuracyLevel& level, Scene* scene) {
  scene->render = level.render;
  if (level.volume) scene->volume = *level.volume;
  scene->gi.display_fraction = level.photon_fraction;
  if (level.lod.groups > 0) {
    scene->gi.lod_groups = level.lod.groups;
    scene->gi.lod_near = level.lod.near;
    scene->gi.lod_far = level.lod.far;
  }
}

std::vector<AccuracyLevel> make_accuracy_ladder(const RenderSettings& full, bool lit,
                                                const PhotonLod& lod) {
  // The cheap integration: a 32x32 table (the paper's size) with the chord and
  // warped layouts, which keep it accurate where g varies fastest
  // (docs/accuracy.md); a scene already at or below that keeps its own.
  RenderSettings fast = full;
  if (full.method == IntegrationMethod::kTable) {
    fast.table_d = std::min(full.table_d, 32);
    fast.table_s = std::min(full.table_s, 32);
  } else {
    fast.method = IntegrationMethod::kTable;
    fast.table_d = 32;
    fast.table_s = 32;
    fast.layout = TableLayout::kChordWarped;
  }
  fast.filter = TableFilter::kHardware;

  std::vector<AccuracyLevel> ladder;
  ladder.push_back({"full", 1.0, full, 92, 1.0, {}, {}});
  const double photons = lit ? kPreviewPhotonFraction : 1.0;
  const std::string fast_name = settings_label(fast) + (lit ? "+photons1/4" : "");
  if (lit || !same_settings(fast, full)) ladder.push_back({fast_name, 1.0, fast, 90, photons, {}, {}});
  // Resolution is the knob that pays on any renderer: cost follows pixel count.
  ladder.push_back({fast_name + "@3/4", 0.75, fast, 85, photons, {}, {}});
  ladder.push_back({fast_name + "@1/2", 0.5, fast, 80, photons, {}, {}});
  ladder.push_back({fast_name + "@1/4", 0.25, fast, 75, photons, {}, {}});
  // Photon LOD last: on the fog stage it costs more error than a step of
  // resolution at equal time (docs/media.md), so it only extends the
  // ladder below its cheapest level.
  if (lit && lod.groups > 0) ladder.push_back({fast_name + "+lod@1/4", 0.25, fast, 75, photons, lod, {}});
  return ladder;
}

std::vector<AccuracyLevel> make_volume_ladder(const RenderSettings& full, const VolumeSettings& vol) {
  // The beams' cheap integration as in make_accuracy_ladder's second level.
  const RenderSettings fast = make_accuracy_ladder(full).back().render;
  std::vector<AccuracyLevel> ladder;
  ladder.push_back({"full", 1.0, full, 92, 1.0, {}, vol});
  VolumeSettings v = vol;
  v.samples_per_voxel = std::min(vol.samples_per_voxel, 1.0);
  v.ert_threshold = std::min(vol.ert_threshold, 0.98);
  ladder.push_back({"sz1", 1.0, fast, 90, 1.0, {}, v});
  ladder.push_back({"sz1@3/4", 0.75, fast, 85, 1.0, {}, v});
  ladder.push_back({"sz1@1/2", 0.5, fast, 80, 1.0, {}, v});
  v.samples_per_voxel = std::min(vol.samples_per_voxel, 0.5);
  ladder.push_back({"sz1/2@1/2", 0.5, fast, 80, 1.0, {}, v});
  v.level = std::max(vol.level, 1);
  ladder.push_back({"sz1/2+rv1@1/2", 0.5, fast, 80, 1.0, {}, v});
  ladder.push_back({"sz1/2+rv1@1/4", 0.25, fast, 75, 1.0, {}, v});
  return ladder;
}

PoseKey pose_key(const std::vector<Camera>& cameras) {
  PoseKey k;
  for (const Camera& c : cameras) {
    k.insert(k.end(), c.position.begin(), c.position.end());
    if (c.target) {
      k.push_back(1.0);
      k.insert(k.end(), c.target->begin(), c.target->end());
    }
    if (c.rotation) {
      k.push_back(2.0);
      k.insert(k.end(), c.rotation->begin(), c.rotation->end());
    }
    k.insert(k.end(), c.up.begin(), c.up.end());
    k.insert(k.end(), {static_cast<double>(c.projection), c.fov_y_deg, c.ortho_height,
                       c.near_plane, c.far_plane, static_cast<double>(c.width),
                       static_cast<double>(c.height)});
  }
  return k;
}

AccuracyController::AccuracyController(std::vector<AccuracyLevel> ladder, ControllerConfig config)
    : ladder_(std::move(ladder)), config_(config), costs_(ladder_.size()) {}

double AccuracyController::pixels(int level) const {
  const double s = ladder_[level].scale;
  return s * s;
}

std::optional<double> AccuracyController::estimate(int level, double now_ms) const {
  int freshest = -1;
  for (int k = 0; k < static_cast<int>(costs_.size()); ++k) {
    if (costs_[k].last_ms >= 0 && (freshest < 0 || costs_[k].last_ms > costs_[freshest].last_ms)) {
      freshest = k;
    }
  }
  if (freshest < 0) return std::nullopt;
  // Prediction from measurements: cost = fixed + per_pixel * scale². With a
  // fresh measurement at a second scale both terms are fitted (the fixed part
  // is read-back and encoding at the output size, which scaling does not
  // shrink); with one, cost is taken as proportional to pixel count.
  const Cost& a = costs_[freshest];
  int second = -1;
  for (int k = 0; k < static_cast<int>(costs_.size()); ++k) {
    if (costs_[k].last_ms < 0 || pixels(k) == pixels(freshest)) continue;
    if (now_ms - costs_[k].last_ms > config_.stale_ms) continue;
    if (second < 0 || costs_[k].last_ms > costs_[second].last_ms) second = k;
  }
  double predicted = a.ewma_ms * pixels(level) / pixels(freshest);
  if (second >= 0) {
    const double per_pixel =
        (a.ewma_ms - costs_[second].ewma_ms) / (pixels(freshest) - pixels(second));
    if (per_pixel > 0.0) {
      const double fixed = std::max(0.0, a.ewma_ms - per_pixel * pixels(freshest));
      predicted = fixed + per_pixel * pixels(level);
    }
  }
  const Cost& own = costs_[level];
  if (own.last_ms < 0) return predicted;
  if (now_ms - own.last_ms <= config_.stale_ms || level == freshest) return own.ewma_ms;
  // A stale measurement may date from a busier moment: let the prediction
  // offer a probe, which a fresh measurement then confirms or refutes.
  return std::min(own.ewma_ms, predicted);
}

void AccuracyController::observe(int level, double frame_ms, double now_ms) {
  if (level < 0 || level >= static_cast<int>(costs_.size()) || !std::isfinite(frame_ms)) return;
  Cost& c = costs_[level];
  c.ewma_ms = c.last_ms < 0 ? frame_ms
                            : config_.ewma_alpha * frame_ms + (1.0 - config_.ewma_alpha) * c.ewma_ms;
  c.last_ms = now_ms;
}

ControllerDecision AccuracyController::decide(double now_ms, const PoseKey& pose, Motion motion) {
  ControllerDecision d;
  const bool first = !last_pose_.has_value();
  d.moving = motion == Motion::kMoving ||
             (motion == Motion::kInfer && !first && *last_pose_ != pose);
  last_pose_ = pose;
  if (d.moving) {
    last_motion_ms_ = now_ms;
    ever_moved_ = true;
  }
  const double still_for =
      ever_moved_ ? now_ms - last_motion_ms_ : std::numeric_limits<double>::infinity();
  const int n = static_cast<int>(ladder_.size());

  if (motion == Motion::kStill || (!d.moving && still_for >= config_.still_ms)) {
    // The still frame: full accuracy whatever it costs. The interactive level
    // is kept, so the next motion resumes from where it was.
    d.level = 0;
    d.still = true;
    d.reason = first ? "first_frame" : "still";
  } else if (level_ < 0) {
    // First moving frame: start at the most accurate level predicted to fit;
    // with nothing measured yet, at the cheapest (the calibration frame).
    level_ = n - 1;
    for (int l = 0; l < n; ++l) {
      const auto e = estimate(l, now_ms);
      if (e && *e <= config_.budget_ms) {
        level_ = l;
        break;
      }
    }
    d.level = level_;
    d.reason = d.moving ? "moving" : "settling";
  } else {
    const auto cur = estimate(level_, now_ms);
    const auto finer = level_ > 0 ? estimate(level_ - 1, now_ms) : std::nullopt;
    if (cur && *cur > config_.budget_ms && level_ < n - 1) {
      ++level_;
      d.reason = "over_budget";
    } else if (finer && *finer <= config_.climb_margin * config_.budget_ms) {
      --level_;
      d.reason = "under_budget";
    } else {
      d.reason = d.moving ? "moving" : "settling";
    }
    d.level = level_;
  }
  d.estimate_ms = estimate(d.level, now_ms).value_or(0.0);
  return d;
}

}  // namespace beamcast
