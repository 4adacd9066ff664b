// The accuracy controller (render/accuracy_controller.hpp) without GL: fed
// synthetic frame costs and a synthetic clock.
#include <gtest/gtest.h>

#include "render/accuracy_controller.hpp"

namespace beamcast {
namespace {

PoseKey pose(double x) { return {x, 0.0, 5.0}; }

// Per-level cost model for the tests: 100 ms at full accuracy, 90 ms for the
// cheap table at scale 1, then proportional to pixel count.
double cost(const AccuracyLevel& l, bool full) { return (full ? 100.0 : 90.0) * l.scale * l.scale; }

TEST(AccuracyLadder, StartsAtTheSceneSettingsAndGetsCheaper) {
  const RenderSettings full;  // chord_warped 128x128
  const auto ladder = make_accuracy_ladder(full);
  ASSERT_GE(ladder.size(), 4u);
  EXPECT_EQ(ladder[0].scale, 1.0);
  EXPECT_EQ(ladder[0].render.table_d, full.table_d);
  EXPECT_EQ(ladder[0].label, "full");
  for (std::size_t i = 1; i < ladder.size(); ++i) {
    EXPECT_LE(ladder[i].scale, ladder[i - 1].scale) << i;
    EXPECT_LE(ladder[i].render.table_d, ladder[i - 1].render.table_d) << i;
    EXPECT_LE(ladder[i].jpeg_quality, ladder[i - 1].jpeg_quality) << i;
  }
  EXPECT_EQ(ladder.back().scale, 0.25);
}

TEST(AccuracyLadder, VolumeScenesChangeOneKnobAStep) {
  VolumeSettings vol;  // 2 samples a voxel, ERT 0.99, level 0
  Scene scene;
  scene.volumes.push_back(procedural_volume(VolumeSourceType::kHeat, 4));
  scene.volume = vol;
  const auto ladder = preview_ladder(scene);
  ASSERT_EQ(ladder.size(), 7u);
  ASSERT_TRUE(ladder[0].volume.has_value());
  EXPECT_EQ(ladder[0].volume->samples_per_voxel, 2.0);
  EXPECT_EQ(ladder[0].scale, 1.0);
  // Each step below full changes one of S_z, S_xy and R_v (ERT and the
  // beams' table change with the first), never back up.
  for (std::size_t i = 2; i < ladder.size(); ++i) {
    const AccuracyLevel& a = ladder[i - 1];
    const AccuracyLevel& b = ladder[i];
    ASSERT_TRUE(b.volume.has_value());
    const int changed = (a.scale != b.scale) +
                        (a.volume->samples_per_voxel != b.volume->samples_per_voxel) +
                        (a.volume->level != b.volume->level);
    EXPECT_EQ(changed, 1) << b.label;
    EXPECT_LE(b.scale, a.scale);
    EXPECT_LE(b.volume->samples_per_voxel, a.volume->samples_per_voxel);
    EXPECT_GE(b.volume->level, a.volume->level);
    EXPECT_TRUE(b.volume->opacity_correction);  // what keeps the brightness level to level
  }
  EXPECT_EQ(ladder.back().scale, 0.25);
  EXPECT_EQ(ladder.back().volume->level, 1);
  // Applying a level sets the scene's volume settings.
  Scene moved = scene;
  apply_accuracy_level(ladder[4], &moved);
  EXPECT_EQ(moved.volume.samples_per_voxel, 0.5);
}

TEST(AccuracyLadder, MarchingSceneGetsATableAsItsCheapIntegration) {
  RenderSettings full;
  full.method = IntegrationMethod::kMarch;
  full.samples = 256;
  const auto ladder = make_accuracy_ladder(full);
  EXPECT_EQ(ladder[0].render.method, IntegrationMethod::kMarch);
  EXPECT_EQ(ladder[1].render.method, IntegrationMethod::kTable);
  EXPECT_EQ(ladder[1].scale, 1.0);
}

TEST(AccuracyLadder, SmallTableSceneSkipsTheEqualLevel) {
  RenderSettings full;
  full.table_d = full.table_s = 32;
  const auto ladder = make_accuracy_ladder(full);
  ASSERT_EQ(ladder.size(), 4u);  // full, 3/4, 1/2, 1/4
  EXPECT_EQ(ladder[1].scale, 0.75);
}

// A lit scene's levels below the full one splat a quarter of the cached
// photons; an unlit scene's ladder is unchanged (every level all of them).
TEST(AccuracyLadder, LitScenesSplatAShareOfThePhotonsBelowFull) {
  const RenderSettings full;
  const auto lit = make_accuracy_ladder(full, true);
  ASSERT_GE(lit.size(), 2u);
  EXPECT_EQ(lit[0].photon_fraction, 1.0);
  EXPECT_EQ(lit[0].label, "full");
  for (std::size_t i = 1; i < lit.size(); ++i) {
    EXPECT_EQ(lit[i].photon_fraction, kPreviewPhotonFraction) << lit[i].label;
    EXPECT_NE(lit[i].label.find("photons1/4"), std::string::npos) << lit[i].label;
  }
  EXPECT_EQ(lit[1].scale, 1.0);
  const auto unlit = make_accuracy_ladder(full, false);
  for (const AccuracyLevel& l : unlit) EXPECT_EQ(l.photon_fraction, 1.0) << l.label;
  EXPECT_EQ(unlit.size(), make_accuracy_ladder(full).size());
}

// Issue 15's LOD knob: with a preview LOD a lit scene's ladder gets one
// level more, the cheapest level thinned by LOD too, at its end; no other
// level has LOD, and a scene's own gi.lod (every frame has it) gets no
// second one. apply_accuracy_level writes the level's LOD into the scene.
TEST(AccuracyLadder, LitScenesThinTheirPhotonsByLodLast) {
  const RenderSettings full;
  GiSettings gi;
  const PhotonLod lod = preview_lod(gi, 12.0);
  EXPECT_EQ(lod.groups, 16);
  EXPECT_EQ(lod.near, 12.0);  // near > far: the nearest photons thinned most
  EXPECT_EQ(lod.far, 0.0);
  const auto plain = make_accuracy_ladder(full, true);
  const auto ladder = make_accuracy_ladder(full, true, lod);
  ASSERT_EQ(ladder.size(), plain.size() + 1);
  for (std::size_t i = 0; i < plain.size(); ++i) {
    EXPECT_EQ(ladder[i].label, plain[i].label);
    EXPECT_EQ(ladder[i].lod.groups, 0) << ladder[i].label;
  }
  const AccuracyLevel& last = ladder.back();
  EXPECT_EQ(last.lod.groups, 16);
  EXPECT_EQ(last.scale, plain.back().scale);
  EXPECT_EQ(last.photon_fraction, plain.back().photon_fraction);
  EXPECT_NE(last.label.find("lod"), std::string::npos) << last.label;
  Scene scene;
  apply_accuracy_level(last, &scene);
  EXPECT_EQ(scene.gi.lod_groups, 16);
  EXPECT_EQ(scene.gi.lod_near, 12.0);
  EXPECT_EQ(scene.gi.display_fraction, kPreviewPhotonFraction);
  apply_accuracy_level(ladder[0], &scene);  // the full level leaves gi.lod as it is
  EXPECT_EQ(scene.gi.display_fraction, 1.0);
  gi.lod_groups = 8;
  EXPECT_EQ(preview_lod(gi, 12.0).groups, 0);
  // Unlit scenes have no photons to thin.
  EXPECT_EQ(make_accuracy_ladder(full, false, lod).size(), make_accuracy_ladder(full).size());
}

TEST(AccuracyController, FirstFrameIsFullAccuracy) {
  AccuracyController c(make_accuracy_ladder({}), {});
  const auto d = c.decide(0.0, pose(0), Motion::kInfer);
  EXPECT_TRUE(d.still);
  EXPECT_EQ(d.level, 0);
  EXPECT_EQ(d.reason, "first_frame");
}

// Runs `frames` moving frames at 20 ms spacing, feeding the cost model back.
int drive(AccuracyController& c, double& t, int frames, std::vector<int>* levels = nullptr) {
  int level = -1;
  for (int i = 0; i < frames; ++i) {
    t += 20.0;
    const auto d = c.decide(t, pose(t), Motion::kInfer);
    EXPECT_TRUE(d.moving);
    EXPECT_FALSE(d.still);
    if (levels && !levels->empty()) {
      EXPECT_LE(std::abs(d.level - levels->back()), 1) << "jumped more than one level at " << i;
    }
    if (levels) levels->push_back(d.level);
    c.observe(d.level, cost(c.ladder()[d.level], d.level == 0), t);
    level = d.level;
  }
  return level;
}

TEST(AccuracyController, SettlesOnTheMostAccurateLevelThatFitsOneStepAtATime) {
  ControllerConfig cfg;
  cfg.budget_ms = 33.0;
  AccuracyController c(make_accuracy_ladder({}), cfg);
  double t = 0.0;
  const auto first = c.decide(t, pose(-1), Motion::kInfer);
  c.observe(first.level, cost(c.ladder()[0], true), t);  // 100 ms full frame
  std::vector<int> levels;
  const int settled = drive(c, t, 30, &levels);
  // Levels: full 100, table 90, 3/4 50.6, 1/2 22.5, 1/4 5.6 ms: 1/2 is the
  // most accurate under 33 ms.
  EXPECT_EQ(c.ladder()[settled].scale, 0.5);
  EXPECT_EQ(levels.back(), settled);
}

TEST(AccuracyController, LargerBudgetGivesMoreAccurateLevel) {
  ControllerConfig cfg;
  cfg.budget_ms = 70.0;  // fits 3/4 (50.6 ms) with the climb margin, not scale 1 (90 ms)
  AccuracyController c(make_accuracy_ladder({}), cfg);
  double t = 0.0;
  c.observe(c.decide(t, pose(-1), Motion::kInfer).level, 100.0, t);
  EXPECT_EQ(c.ladder()[drive(c, t, 30)].scale, 0.75);
}

TEST(AccuracyController, StepsDownWhenFramesGetSlowerAndBackUpWhenFaster) {
  AccuracyController c(make_accuracy_ladder({}), {});
  double t = 0.0;
  c.observe(c.decide(t, pose(-1), Motion::kInfer).level, 100.0, t);
  const int settled = drive(c, t, 20);
  // The machine gets busy: the settled level now costs 3x its budget.
  t += 20.0;
  auto d = c.decide(t, pose(t), Motion::kInfer);
  EXPECT_EQ(d.level, settled);
  c.observe(d.level, 200.0, t);
  c.observe(d.level, 200.0, t);
  c.observe(d.level, 200.0, t);
  t += 20.0;
  d = c.decide(t, pose(t), Motion::kInfer);
  EXPECT_EQ(d.level, settled + 1);
  EXPECT_EQ(d.reason, "over_budget");
  // Still busy a moment later: the slow measurement of the finer level is
  // fresh (within stale_ms), so the controller does not climb back yet.
  c.observe(d.level, 2.0, t);
  t += 20.0;
  d = c.decide(t, pose(t), Motion::kInfer);
  EXPECT_EQ(d.level, settled + 1);
  // Quiet again for longer than stale_ms: the finer level is predicted from
  // the cheap measurements, and the controller climbs one step.
  for (int i = 0; i < 6; ++i) c.observe(d.level, 2.0, t += 400.0);
  t += 20.0;
  d = c.decide(t, pose(t), Motion::kInfer);
  EXPECT_EQ(d.level, settled);
  EXPECT_EQ(d.reason, "under_budget");
}

TEST(AccuracyController, StillCameraGetsFullAccuracyAfterTheStillTime) {
  ControllerConfig cfg;
  cfg.still_ms = 300.0;
  AccuracyController c(make_accuracy_ladder({}), cfg);
  double t = 0.0;
  c.observe(c.decide(t, pose(-1), Motion::kInfer).level, 100.0, t);
  const int settled = drive(c, t, 10);
  const double stopped = t;
  const PoseKey last = pose(t);
  // Same pose, before the still time: interactive frames, "settling".
  t = stopped + 100.0;
  auto d = c.decide(t, last, Motion::kInfer);
  EXPECT_FALSE(d.moving);
  EXPECT_FALSE(d.still);
  EXPECT_EQ(d.reason, "settling");
  // At the still time: the full-accuracy frame.
  t = stopped + 300.0;
  d = c.decide(t, last, Motion::kInfer);
  EXPECT_TRUE(d.still);
  EXPECT_EQ(d.level, 0);
  EXPECT_EQ(d.reason, "still");
  // Moving again resumes at the interactive level, not at full accuracy.
  t += 20.0;
  d = c.decide(t, pose(t), Motion::kInfer);
  EXPECT_EQ(d.level, settled);
  EXPECT_FALSE(d.still);
}

TEST(AccuracyController, ExplicitMotionOverridesInference) {
  AccuracyController c(make_accuracy_ladder({}), {});
  double t = 0.0;
  c.decide(t, pose(0), Motion::kInfer);
  // Same pose but the client says it is moving (e.g. the scene changes).
  auto d = c.decide(t += 20.0, pose(0), Motion::kMoving);
  EXPECT_TRUE(d.moving);
  EXPECT_FALSE(d.still);
  // A different pose but the client says still: full accuracy now.
  d = c.decide(t + 20.0, pose(1), Motion::kStill);
  EXPECT_TRUE(d.still);
  EXPECT_EQ(d.level, 0);
}

TEST(AccuracyController, UnmeasuredLevelsArePredictedFromPixelCount) {
  AccuracyController c(make_accuracy_ladder({}), {});
  EXPECT_FALSE(c.estimate(0, 0.0).has_value());
  c.observe(0, 80.0, 0.0);
  const int last = static_cast<int>(c.ladder().size()) - 1;
  // 1/4 scale: 1/16 of the pixels.
  EXPECT_DOUBLE_EQ(*c.estimate(last, 0.0), 5.0);
  // Its own measurement replaces the prediction.
  c.observe(last, 9.0, 1.0);
  EXPECT_DOUBLE_EQ(*c.estimate(last, 1.0), 9.0);
}

TEST(AccuracyController, PredictionLearnsTheFixedCostFromTwoScales) {
  AccuracyController c(make_accuracy_ladder({}), {});
  const int last = static_cast<int>(c.ladder().size()) - 1;  // scale 1/4
  c.observe(0, 80.0, 0.0);
  c.observe(last, 9.5, 1.0);
  // per pixel (80 - 9.5) / (1 - 1/16) = 75.2, fixed 80 - 75.2 = 4.8: the
  // 1/2 level is 4.8 + 75.2 / 4 = 23.6 ms, not the 20 ms of pure scaling.
  int half = -1;
  for (int l = 0; l <= last; ++l) {
    if (c.ladder()[l].scale == 0.5) half = l;
  }
  ASSERT_GE(half, 0);
  EXPECT_NEAR(*c.estimate(half, 1.0), 23.6, 1e-9);
  // A measurement older than stale_ms is not used for the fit.
  EXPECT_NEAR(*c.estimate(half, 1.0 + c.config().stale_ms + 1.0), 9.5 * 4.0, 1e-9);
}

TEST(AccuracyController, EwmaFollowsTheMeasurements) {
  ControllerConfig cfg;
  cfg.ewma_alpha = 0.5;
  AccuracyController c(make_accuracy_ladder({}), cfg);
  c.observe(1, 10.0, 0.0);
  c.observe(1, 20.0, 1.0);
  EXPECT_DOUBLE_EQ(*c.estimate(1, 1.0), 15.0);
  c.observe(1, 20.0, 2.0);
  EXPECT_DOUBLE_EQ(*c.estimate(1, 2.0), 17.5);
}

TEST(AccuracyController, PoseKeySeesEveryCameraChange) {
  Camera a;
  Camera b = a;
  EXPECT_EQ(pose_key({a}), pose_key({b}));
  b.position[0] += 1e-9;
  EXPECT_NE(pose_key({a}), pose_key({b}));
  b = a;
  b.width = 256;
  EXPECT_NE(pose_key({a}), pose_key({b}));
  b = a;
  b.target = Vec3{0, 0, 0};
  EXPECT_NE(pose_key({a}), pose_key({b}));
}

}  // namespace
}  // namespace beamcast
