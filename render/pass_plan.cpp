#include "render/pass_plan.hpp"

#include "gi/photon_map.hpp"
#include "protocol/occluders/slim.hpp"

#include <algorithm>

namespace beamcast {

namespace {

template <class T>
bool contains(const std::vector<T>& v, std::string_view s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

}  // namespace

bool interleaves_direct_points(const GiSettings& gi, std::size_t points) {
  return gi.direct_interleave == 4 && points > 0 && points % 4 == 0;
}

namespace {

// The direct pass runs: occluders to light, lights, gi.direct "shadow_maps".
bool shadow_mapped_direct(const Scene& scene) {
  return !scene.occluders.empty() && scene.has_gi() &&
         scene.gi.direct == DirectLightMethod::kShadowMaps;
}

// The volume photons' light by the grid (medium.estimator "grid"), not splats.
bool grid_estimate(const Scene& scene) {
  return scene.medium.value_or(Medium{}).estimator == VolumeEstimator::kGrid;
}

}  // namespace

bool interleaves_direct(const Scene& scene) {
  return std::any_of(scene.lights.begin(), scene.lights.end(), [&](const Light& l) {
    const std::size_t n = std::visit(
        [&](const auto& kind) { return kind.direct_points(scene.gi.direct_samples).size(); },
        l.shape);
    return interleaves_direct_points(scene.gi, n);
  });
}

const std::vector<TargetDecl>& target_catalog() {
  static const std::vector<TargetDecl> kTargets = {
      {"hdr", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kBackground},
      {"view_depth", TargetFormat::kR32f, TargetSize::kRender, TargetClear::kNoSurface},
      {"depth", TargetFormat::kDepth32f, TargetSize::kRender, TargetClear::kFarDepth},
      {"output", TargetFormat::kDisplay, TargetSize::kRender, TargetClear::kNone},
      {"upscaled", TargetFormat::kDisplay, TargetSize::kCamera, TargetClear::kNone},
      // G-buffer of lit (global illumination) scenes: the surface normal
      // facing the camera, and albedo with the material code (w).
      {"gb_normal", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kNone},
      {"gb_albedo", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kNone},
      // What the photon splats add up, before the edge correction (gi_resolve).
      // At gi.splat_scale times fewer pixels per side (indirect light is smooth).
      {"gi_indirect", TargetFormat::kRgba32f, TargetSize::kSplat, TargetClear::kZero},
      // SLIM point sampling (render/slim_pass.cpp): the nearest view depth
      // per pixel (field evaluation: on the pixel's centre ray, with the
      // smallest owning sphere's radius), then the sums of what lies within
      // the depth threshold behind it: blend (the seed's) (w n, w) and
      // (w albedo, w view depth); field F's terms at two points of the
      // centre ray, (w grad h + h grad w, w h) and (grad w, w), and
      // (w albedo, -). The slim passes clear these themselves, over the
      // surfaces' pixel bounds only (render/slim_pass.cpp). The resolved
      // surface: (unit normal, view depth), zero where none.
      {"slim_near", TargetFormat::kR32f, TargetSize::kRender, TargetClear::kNone},
      {"slim_radius", TargetFormat::kR32f, TargetSize::kRender, TargetClear::kNone},
      // slim.evaluation "patch": slim_near as a depth buffer, which culls
      // the accumulate pass's hidden patches before their fragments run
      // (written over the surfaces' pixel bounds before each use; outside
      // them no patch can be, so it is never cleared).
      {"slim_zbuf", TargetFormat::kDepth32f, TargetSize::kRender, TargetClear::kNone},
      {"slim_sum_albedo", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kNone},
      {"slim_sum_field", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kNone},
      {"slim_sum_weight", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kNone},
      {"slim_sum_field2", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kNone},
      {"slim_sum_weight2", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kNone},
      {"slim_surface", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kZero},
      // The volumes' transmittance along each pixel's ray, for the beams
      // behind and inside them (shaders/volume_knots.glsl): the ray's
      // interval in the box around all volumes cut into 7 equal segments,
      // the transmittance at each one's middle (volume_t0: segments 0-3,
      // volume_t1: 4-6) and at the interval's end (volume_t1.w); products
      // over the volumes, so cleared to one.
      {"volume_t0", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kOne},
      {"volume_t1", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kOne},
      // The interleaved direct points' irradiance, each pixel's quarter at 4
      // times the weight (w: the view depth where a diffuse surface was lit, else 0), before the
      // gi_resolve pass brings the four quarters together.
      {"direct_split", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kZero},
      // What mirror and glass pixels show, found on the CPU (render/specular_pass.hpp).
      {"specular", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kZero},
  };
  return kTargets;
}

const std::vector<PassDecl>& pass_catalog() {
  static const std::vector<PassDecl> kCatalog = {
      // Occluders lit by the directional light: shaded colour, the view depth
      // of the nearest surface, depth.
      {PassId::kSurfaces, "surfaces",
       [](const PlanInput& in) { return !in.scene.occluders.empty() && !in.scene.has_gi(); }, {}, {},
       {"hdr", "view_depth", "depth"}, {"occluders"}},
      // Occluders of a lit scene (scene lights): the same draws into a
      // G-buffer (view depth, normal, albedo and material); hdr gets what
      // the surfaces emit (nothing yet) in place of the background.
      {PassId::kGbuffer, "gbuffer",
       [](const PlanInput& in) { return !in.scene.occluders.empty() && in.scene.has_gi(); }, {}, {},
       {"hdr", "view_depth", "gb_normal", "gb_albedo", "depth"}, {"occluders"}},
      // SLIM surfaces (seed 003; render/slim_pass.cpp): points sampled on each
      // support sphere's local height field, drawn three times: the nearest
      // point per pixel, the weighted sums of the points within the depth
      // threshold behind it, and their normalization into the surfaces'
      // targets (before the lighting passes, which shade them like any
      // occluder). Points behind a nearer occluder are dropped.
      {PassId::kSlimDepth, "slim_depth", [](const PlanInput& in) { return has_slim(in.scene); },
       {"view_depth"}, {}, {"slim_near", "slim_radius"}, {"slim"}},
      {PassId::kSlimAccumulate, "slim_accumulate",
       [](const PlanInput& in) { return has_slim(in.scene); },
       {"view_depth", "slim_near", "slim_radius"}, {},
       {"slim_sum_albedo", "slim_sum_field", "slim_sum_weight", "slim_sum_field2",
        "slim_sum_weight2", "slim_zbuf"},
       {"slim"}},
      {PassId::kSlimResolve, "slim_resolve",
       [](const PlanInput& in) { return has_slim(in.scene) && !in.scene.has_gi(); },
       {"slim_sum_albedo", "slim_sum_field", "slim_sum_weight", "slim_near",
        "slim_sum_field2", "slim_sum_weight2", "slim_radius"},
       {},
       {"hdr", "view_depth", "slim_surface"}, {}},
      {PassId::kSlimGbuffer, "slim_gbuffer",
       [](const PlanInput& in) { return has_slim(in.scene) && in.scene.has_gi(); },
       {"slim_sum_albedo", "slim_sum_field", "slim_sum_weight", "slim_near",
        "slim_sum_field2", "slim_sum_weight2", "slim_radius"},
       {},
       {"hdr", "view_depth", "slim_surface", "gb_normal", "gb_albedo"}, {}},
      // Direct light of a lit scene (gi.direct "shadow_maps"): every light as
      // a few point emitters (DirectPoint), each with a cube shadow map of
      // the triangles (rendered once per scene and kept) and shadow rays to
      // the analytic occluders; adds what diffuse surfaces reflect to hdr.
      {PassId::kDirect, "direct",
       [](const PlanInput& in) {
         return shadow_mapped_direct(in.scene) && !interleaves_direct(in.scene);
       },
       {"hdr", "view_depth", "gb_normal", "gb_albedo"}, {}, {"hdr"}, {"shadows"}},
      // The same with gi.direct_interleave 4 (interleaved sampling): each
      // pixel sums a quarter of each interleaved light's points (by its
      // place in a 2 x 2 pattern) into direct_split, the other lights' points
      // into hdr as above; gi_resolve then averages the four quarters
      // over each pixel's 3 x 3 neighbours on its own surface.
      {PassId::kDirectSplit, "direct",
       [](const PlanInput& in) {
         return shadow_mapped_direct(in.scene) && interleaves_direct(in.scene);
       },
       {"hdr", "view_depth", "gb_normal", "gb_albedo"}, {}, {"hdr", "direct_split"}, {"shadows"}},
      // Photon splatting (seed 001, section 4.2): one camera-facing disk per
      // photon adds its reflected radiance to the G-buffer's pixels within
      // the radius (without the photons straight from a light when the
      // direct pass carries that light).
      {PassId::kPhotons, "photons",
       [](const PlanInput& in) { return !in.scene.occluders.empty() && in.scene.has_gi(); },
       {"view_depth", "gb_normal", "gb_albedo"}, {}, {"gi_indirect"}, {"photons"}},
      // The splats' sum to hdr, divided by the share of each pixel's disk
      // that its surface covers (found in the G-buffer), so a surface's
      // edges and the room's corners are not darkened by the disk hanging
      // over them (gi.edge_correction; shaders/gi_resolve.frag). With the
      // interleaved direct light (direct_split written) the same pass
      // brings its four quarters together (shaders/direct_filter.glsl).
      {PassId::kGiResolve, "gi_resolve",
       [](const PlanInput& in) { return !in.scene.occluders.empty() && in.scene.has_gi(); },
       {"hdr", "gi_indirect", "view_depth", "gb_normal", "gb_albedo"}, {"direct_split"}, {"hdr"},
       {}},
      // Mirror and glass pixels of a lit scene: the CPU follows their centre
      // rays to what they reach and the radiance there is added to hdr
      // (render/specular_pass.hpp).
      {PassId::kSpecular, "specular",
       [](const PlanInput& in) { return in.scene.has_gi() && has_specular(in.scene); },
       {"hdr", "gb_albedo", "specular"}, {}, {"hdr"}, {"specular"}},
      // A medium filling the scene (render/medium_pass.hpp): what reached
      // hdr so far (surfaces, background) attenuated by the distance to it;
      // the beams attenuate their own light.
      {PassId::kMedium, "medium", [](const PlanInput& in) { return in.scene.has_medium(); },
       {"hdr"}, {"view_depth"}, {"hdr"}, {}},
      // Light the medium scatters towards the eye in a lit scene: the volume
      // photons (the global map's scattering events), each a camera-facing
      // quad over its kernel, added to hdr up to the nearest surface
      // (render/medium_pass.hpp; medium.estimator picks the estimate).
      {PassId::kVolumePhotons, "volume_photons",
       [](const PlanInput& in) {
         return in.scene.has_gi() && in.scene.medium_scatters() && !grid_estimate(in.scene);
       },
       {"hdr"}, {"view_depth"}, {"hdr"}, {"volume_photons"}},
      // The same light without splats (medium.estimator "grid", the
      // default; render/volume_grid.hpp): the volume photons binned into a
      // world grid each frame (compute), each pixel's ray marched through it.
      {PassId::kVolumeGrid, "volume_grid",
       [](const PlanInput& in) {
         return in.scene.has_gi() && in.scene.medium_scatters() && grid_estimate(in.scene);
       },
       {"hdr"}, {"view_depth"}, {"hdr"}, {"volume_grid"}},
      // Scalar volumes (seed 004; render/volume_pass.hpp): each ray cast up
      // to the nearest surface and composited over hdr, farther volumes
      // first; with beams in the scene, the same pass also writes the
      // transmittance knots they read (two float targets cleared and
      // blended: 12 ms of a 512^2 frame on llvmpipe, not paid without beams).
      {PassId::kVolumes, "volumes",
       [](const PlanInput& in) { return !in.scene.volumes.empty() && in.scene.beams.empty(); },
       {"hdr"}, {"view_depth"}, {"hdr"}, {"volumes"}},
      {PassId::kVolumesForBeams, "volumes",
       [](const PlanInput& in) { return !in.scene.volumes.empty() && !in.scene.beams.empty(); },
       {"hdr"}, {"view_depth"}, {"hdr", "volume_t0", "volume_t1"}, {"volumes"}},
      // Beams: energy added to hdr; a ray ends at the nearest surface if
      // anything wrote view_depth.
      {PassId::kBeams, "beams", [](const PlanInput& in) { return !in.scene.beams.empty(); },
       {"hdr"}, {"view_depth", "volume_t0", "volume_t1"}, {"hdr"}, {"beams"}},
      // Every frame is tone-mapped into its output format.
      {PassId::kTonemap, "tonemap", [](const PlanInput&) { return true; }, {"hdr"}, {}, {"output"},
       {}},
      // Scaled frames (interactive preview): bilinear blit to the camera's size.
      {PassId::kUpscale, "upscale", [](const PlanInput& in) { return in.scaled(); }, {"output"}, {},
       {"upscaled"}, {}},
  };
  return kCatalog;
}

bool FramePlan::written(std::string_view target) const {
  return std::any_of(passes.begin(), passes.end(),
                     [&](const PassDecl* p) { return contains(p->writes, target); });
}

bool FramePlan::uses(std::string_view target) const {
  return std::any_of(targets.begin(), targets.end(),
                     [&](const TargetDecl* t) { return t->name == target; });
}

bool FramePlan::uploads_group(std::string_view group) const { return contains(uploads, group); }

std::vector<std::string> FramePlan::names() const {
  std::vector<std::string> out;
  for (const PassDecl* p : passes) out.push_back(p->name);
  return out;
}

FramePlan make_plan(const PlanInput& in, const std::vector<PassDecl>& catalog,
                    const std::vector<TargetDecl>& targets) {
  FramePlan plan;
  plan.splat_scale = in.scene.gi.splat_scale;
  if (in.scene.has_gi() && has_specular(in.scene) && in.scene.gi.caustic_photons > 0) {
    plan.auto_splat_cap = 2;
  }
  auto target = [&](const PassDecl& pass, const std::string& name) -> const TargetDecl* {
    for (const TargetDecl& t : targets) {
      if (t.name == name) return &t;
    }
    throw PlanError("pass \"" + pass.name + "\" names target \"" + name +
                    "\", which is not in the target catalog");
  };
  auto use = [&](const TargetDecl* t) {
    if (std::find(plan.targets.begin(), plan.targets.end(), t) == plan.targets.end()) {
      plan.targets.push_back(t);
    }
  };
  std::vector<PassId> seen;
  for (const PassDecl& pass : catalog) {
    if (std::find(seen.begin(), seen.end(), pass.id) != seen.end()) {
      throw PlanError("pass \"" + pass.name + "\" repeats the id of an earlier pass");
    }
    seen.push_back(pass.id);
    if (!pass.needed(in)) continue;
    for (const std::string& r : pass.reads) {
      const TargetDecl* t = target(pass, r);
      if (t->clear == TargetClear::kNone && !plan.written(r)) {
        throw PlanError("pass \"" + pass.name + "\" reads target \"" + r +
                        "\", which no earlier planned pass writes and nothing clears");
      }
      use(t);
    }
    for (const std::string& r : pass.optional_reads) {
      const TargetDecl* t = target(pass, r);
      if (plan.written(r)) use(t);
    }
    for (const std::string& w : pass.writes) use(target(pass, w));
    for (const std::string& u : pass.uploads) {
      if (!contains(plan.uploads, u)) plan.uploads.push_back(u);
    }
    plan.passes.push_back(&pass);
  }
  if (!plan.passes.empty() && !plan.passes.back()->writes.empty()) {
    plan.final_target = plan.passes.back()->writes.front();
  }
  return plan;
}

std::vector<std::string> plan_passes(const Scene& scene, double resolution_scale) {
  return make_plan(PlanInput{scene, resolution_scale}).names();
}

}  // namespace beamcast
