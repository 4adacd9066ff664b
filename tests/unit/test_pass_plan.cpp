// The pass graph without GL: plans derived from the catalog's declarations,
// and the errors a broken declaration raises at plan time.
#include "render/pass_plan.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

namespace beamcast {
namespace {

Scene scene_with(bool beams, bool occluders, bool lit = false, bool slim = false,
                 bool mirror = false, bool fog = false, bool volume = false) {
  Scene s;
  if (volume) s.volumes.push_back(procedural_volume(VolumeSourceType::kHeat, 4));
  if (fog) s.medium = Medium{.sigma_s = 0.1};
  if (beams) s.beams.emplace_back();
  if (occluders) s.occluders.push_back(Occluder{SphereOccluder{}, {0.5, 0.5, 0.5}, {}});
  if (occluders && mirror) s.occluders[0].material.type = MaterialType::kMirror;
  if (lit) s.lights.push_back(Light{PointLight{}, {1.0, 1.0, 1.0}});
  if (slim) {
    s.occluders.push_back(Occluder{SlimOccluder::from_spheres({SlimSphere{}}), {0.5, 0.5, 0.5}, {}});
  }
  return s;
}

std::vector<std::string> target_names(const FramePlan& plan) {
  std::vector<std::string> out;
  for (const TargetDecl* t : plan.targets) out.push_back(t->name);
  std::sort(out.begin(), out.end());
  return out;
}

TEST(PassPlan, BeamOnlySceneAllocatesNoSurfaceTargets) {
  const FramePlan plan = make_plan(PlanInput{scene_with(true, false)});
  EXPECT_EQ(plan.names(), (std::vector<std::string>{"beams", "tonemap"}));
  // view_depth is an optional read of the beams: nobody writes it, so it is
  // neither allocated nor reported as written; nor is the depth buffer.
  EXPECT_FALSE(plan.written(TargetId::kViewDepth));
  EXPECT_EQ(target_names(plan), (std::vector<std::string>{"hdr", "output"}));
  EXPECT_EQ(plan.uploads, (std::vector<UploadGroup>{UploadGroup::kBeams}));
  EXPECT_EQ(plan.final_target, TargetId::kOutput);
}

TEST(PassPlan, VolumesWriteTransmittanceKnotsThatBeamsRead) {
  const FramePlan plan =
      make_plan(PlanInput{scene_with(true, false, false, false, false, false, true)});
  EXPECT_EQ(plan.names(), (std::vector<std::string>{"volumes", "beams", "tonemap"}));
  EXPECT_TRUE(plan.written(TargetId::kVolumeT0));
  EXPECT_EQ(target_names(plan),
            (std::vector<std::string>{"hdr", "output", "volume_t0", "volume_t1"}));
  EXPECT_EQ(plan.uploads, (std::vector<UploadGroup>{UploadGroup::kVolumes, UploadGroup::kBeams}));
}

TEST(PassPlan, OccludersWriteViewDepthThatBeamsRead) {
  const FramePlan plan = make_plan(PlanInput{scene_with(true, true)});
  EXPECT_EQ(plan.names(), (std::vector<std::string>{"surfaces", "beams", "tonemap"}));
  EXPECT_TRUE(plan.written(TargetId::kViewDepth));
  EXPECT_EQ(target_names(plan),
            (std::vector<std::string>{"depth", "hdr", "output", "view_depth"}));
  EXPECT_TRUE(plan.uploads_group(UploadGroup::kOccluders));
  EXPECT_TRUE(plan.uploads_group(UploadGroup::kBeams));
}

TEST(PassPlan, EmptySceneOnlyTonemapsTheClearedBackground) {
  const FramePlan plan = make_plan(PlanInput{scene_with(false, false)});
  EXPECT_EQ(plan.names(), (std::vector<std::string>{"tonemap"}));
  EXPECT_TRUE(plan.uploads.empty());
}

TEST(PassPlan, ScaledFramesEndWithUpscale) {
  const FramePlan plan = make_plan(PlanInput{scene_with(true, false), 0.5});
  EXPECT_EQ(plan.names(), (std::vector<std::string>{"beams", "tonemap", "upscale"}));
  EXPECT_EQ(plan.final_target, TargetId::kUpscaled);
  // Scale 1 (and out-of-range values, which the server never sends) is native.
  EXPECT_EQ(plan_passes(scene_with(true, false), 1.0).back(), "tonemap");
}

// Every declaration of the built-in catalog is planned for some input, so no
// rule is dead, and every pass writes something.
TEST(PassPlan, EveryCatalogPassIsReachable) {
  std::vector<std::string> seen;
  for (bool b : {false, true}) {
    for (bool o : {false, true}) {
      for (bool lit : {false, true}) {
        for (bool slim : {false, true}) {
          for (bool mirror : {false, true}) {
            for (bool fog : {false, true}) {
              for (bool vol : {false, true}) {
                for (double scale : {1.0, 0.5}) {
                  for (const auto& n :
                       make_plan(PlanInput{scene_with(b, o, lit, slim, mirror, fog, vol), scale})
                           .names()) {
                    seen.push_back(n);
                  }
                }
              }
            }
          }
        }
      }
    }
  }
  // A quad light's 16 points are interleaved (direct with direct_split).
  Scene quad = scene_with(false, true, true);
  quad.lights[0].shape = QuadLight{};
  for (const auto& n : make_plan(PlanInput{quad}).names()) seen.push_back(n);
  // The fog's photon splats: the volume estimates other than the default grid.
  for (VolumeEstimator est : {VolumeEstimator::kBeam, VolumeEstimator::kSeed}) {
    Scene fog = scene_with(false, true, true, false, false, true);
    fog.medium->estimator = est;
    for (const auto& n : make_plan(PlanInput{fog}).names()) seen.push_back(n);
  }
  for (const PassDecl& p : pass_catalog()) {
    EXPECT_NE(std::find(seen.begin(), seen.end(), p.name), seen.end()) << p.name;
    EXPECT_FALSE(p.writes.empty()) << p.name;
  }
}

bool always(const PlanInput&) { return true; }

TEST(PassPlan, ReadingATargetNobodyWritesFailsAtPlanTime) {
  // gb_normal: a target with no start value (TargetClear::kNone).
  const PassDecl lighting{"lighting", always, {TargetId::kGbNormal}, {}, {TargetId::kHdr}, {}};
  const PassDecl gbuffer{"gbuffer", always, {}, {}, {TargetId::kGbNormal}, {}};
  const Scene scene = scene_with(true, false);
  try {
    make_plan(PlanInput{scene}, {lighting});
    FAIL() << "expected PlanError";
  } catch (const PlanError& e) {
    EXPECT_EQ(std::string(e.what()),
              "pass \"lighting\" reads target \"gb_normal\", which no earlier planned pass "
              "writes and nothing clears");
  }
  // Written too late is not written.
  EXPECT_THROW(make_plan(PlanInput{scene}, {lighting, gbuffer}), PlanError);
  // Written by an earlier pass: planned, and the target is allocated. (A plan
  // points into its catalog, which must outlive it.)
  const std::vector<PassDecl> catalog{gbuffer, lighting};
  const FramePlan plan = make_plan(PlanInput{scene}, catalog);
  EXPECT_EQ(plan.names(), (std::vector<std::string>{"gbuffer", "lighting"}));
  EXPECT_TRUE(plan.uses(TargetId::kGbNormal));
}

// gi.direct_interleave 4 (the default) shares out the points of each light
// with a multiple of 4 of them over the 2 x 2 pixel pattern: a quad light's
// 16 add the direct_split target, which gi_resolve reads (it filters the
// quarters); a point light's one point, or direct_interleave 1, does not.
TEST(PassPlan, QuadLightsInterleaveTheirDirectPoints) {
  Scene quad = scene_with(false, true, true);
  quad.lights[0].shape = QuadLight{};
  EXPECT_TRUE(interleaves_direct(quad));
  const FramePlan plan = make_plan(PlanInput{quad});
  EXPECT_EQ(plan.names(),
            (std::vector<std::string>{"gbuffer", "direct", "photons", "gi_resolve", "tonemap"}));
  EXPECT_TRUE(plan.uses(TargetId::kDirectSplit));
  const auto resolve = std::find_if(plan.passes.begin(), plan.passes.end(),
                                    [](const PassDecl* p) { return p->name == "gi_resolve"; });
  ASSERT_NE(resolve, plan.passes.end());
  EXPECT_EQ((*resolve)->optional_reads, std::vector<TargetId>{TargetId::kDirectSplit});
  // The quad's points, 2 x 2 cells at a time: every fourth spans the light.
  const auto points = std::get<QuadLight>(quad.lights[0].shape).direct_points(16);
  ASSERT_EQ(points.size(), 16u);
  for (int c = 0; c < 4; ++c) {
    Aabb box;
    for (std::size_t i = static_cast<std::size_t>(c); i < points.size(); i += 4) box.grow(points[i].position);
    EXPECT_NEAR(box.hi[0] - box.lo[0], 0.5, 1e-12) << c;  // cells 1/4 wide: centres 2 cells apart
    EXPECT_NEAR(box.hi[2] - box.lo[2], 0.5, 1e-12) << c;
  }
  quad.gi.direct_interleave = 1;
  EXPECT_FALSE(interleaves_direct(quad));
  EXPECT_EQ(make_plan(PlanInput{quad}).names(),
            (std::vector<std::string>{"gbuffer", "direct", "photons", "gi_resolve", "tonemap"}));
  EXPECT_FALSE(make_plan(PlanInput{quad}).uses(TargetId::kDirectSplit));
  EXPECT_FALSE(interleaves_direct(scene_with(false, true, true)));  // a point light
}

// A lit scene (lights) runs the G-buffer, direct light and photon splatting
// in place of the directional-light surfaces; without occluders there is
// nothing to light. With gi.direct "photons" the direct pass does not run.
TEST(PassPlan, LitScenesSplatPhotonsOverAGbuffer) {
  const FramePlan plan = make_plan(PlanInput{scene_with(true, true, true)});
  EXPECT_EQ(plan.names(),
            (std::vector<std::string>{"gbuffer", "direct", "photons", "gi_resolve", "beams", "tonemap"}));
  EXPECT_TRUE(plan.uploads_group(UploadGroup::kShadows));
  Scene photons_only = scene_with(true, true, true);
  photons_only.gi.direct = DirectLightMethod::kPhotons;
  EXPECT_EQ(make_plan(PlanInput{photons_only}).names(),
            (std::vector<std::string>{"gbuffer", "photons", "gi_resolve", "beams", "tonemap"}));
  EXPECT_FALSE(make_plan(PlanInput{photons_only}).uploads_group(UploadGroup::kShadows));
  EXPECT_EQ(target_names(plan),
            (std::vector<std::string>{"depth", "gb_albedo", "gb_normal", "gi_indirect", "hdr",
                                      "output", "view_depth"}));
  EXPECT_TRUE(plan.uploads_group(UploadGroup::kPhotons));
  EXPECT_TRUE(plan.written(TargetId::kViewDepth));
  // Mirror or glass surfaces add the specular pass after the splats' resolve.
  const FramePlan mirror = make_plan(PlanInput{scene_with(true, true, true, false, true)});
  EXPECT_EQ(mirror.names(), (std::vector<std::string>{"gbuffer", "direct", "photons", "gi_resolve",
                                                      "specular", "beams", "tonemap"}));
  EXPECT_TRUE(mirror.uploads_group(UploadGroup::kSpecular));
  EXPECT_FALSE(plan.uploads_group(UploadGroup::kSpecular));
  // A caustic map's small disks cap the automatic splat size at 1/2
  // (docs/gi.md, "Caustics and the splat size"); no caustic photons, no cap.
  EXPECT_EQ(mirror.auto_splat_cap, 2);
  EXPECT_GT(plan.auto_splat_cap, 8);
  Scene no_caustics = scene_with(true, true, true, false, true);
  no_caustics.gi.caustic_photons = 0;
  EXPECT_GT(make_plan(PlanInput{no_caustics}).auto_splat_cap, 8);
  EXPECT_EQ(make_plan(PlanInput{scene_with(true, false, true)}).names(),
            (std::vector<std::string>{"beams", "tonemap"}));
  // Unlit scenes never upload photons.
  EXPECT_FALSE(make_plan(PlanInput{scene_with(true, true)}).uploads_group(UploadGroup::kPhotons));
}

// SLIM surfaces run their three point passes after the other occluders'
// (whose view depth hides points behind them) and before the lighting
// passes, which shade them through the G-buffer; no other scene runs them.
TEST(PassPlan, SlimSurfacesRunThePointPasses) {
  EXPECT_EQ(make_plan(PlanInput{scene_with(true, false, false, true)}).names(),
            (std::vector<std::string>{"surfaces", "slim_depth", "slim_accumulate", "slim_resolve",
                                      "beams", "tonemap"}));
  const FramePlan lit = make_plan(PlanInput{scene_with(false, true, true, true)});
  EXPECT_EQ(lit.names(), (std::vector<std::string>{"gbuffer", "slim_depth", "slim_accumulate",
                                                   "slim_gbuffer", "direct", "photons", "gi_resolve",
                                                   "tonemap"}));
  EXPECT_TRUE(lit.uploads_group(UploadGroup::kSlim));
  for (bool lit_scene : {false, true}) {
    const FramePlan plan = make_plan(PlanInput{scene_with(true, true, lit_scene)});
    EXPECT_FALSE(plan.uploads_group(UploadGroup::kSlim));
    EXPECT_FALSE(plan.uses(TargetId::kSlimNear));
  }
}

// The target catalog holds one declaration per TargetId, in its order
// (FrameTargets indexes by it); every pass row has an executor factory; a
// target missing from the catalog a plan is made with fails at plan time.
TEST(PassPlan, CatalogsAreCompleteAndMissingTargetsFail) {
  const std::vector<TargetDecl>& targets = target_catalog();
  ASSERT_EQ(targets.size(), kTargetCount);
  for (std::size_t i = 0; i < targets.size(); ++i) {
    EXPECT_EQ(static_cast<std::size_t>(targets[i].id), i) << targets[i].name;
  }
  for (const PassDecl& p : pass_catalog()) EXPECT_NE(p.make, nullptr) << p.name;
  std::vector<TargetDecl> no_output;
  for (const TargetDecl& t : targets) {
    if (t.id != TargetId::kOutput) no_output.push_back(t);
  }
  // The tonemap pass (planned for every frame) writes output.
  EXPECT_THROW(make_plan(PlanInput{scene_with(false, false)}, pass_catalog(), no_output), PlanError);
}

}  // namespace
}  // namespace beamcast
