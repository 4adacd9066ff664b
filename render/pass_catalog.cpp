// The pass catalog: one row a pass, in execution order, with when it runs,
// the targets it reads and writes, the per-scene data it uploads and the
// factory of its executor. A new pass is a row here plus its executor's file
// (docs/architecture.md, "Where does a new X go"); the frame loop, the target
// allocation and SceneResources follow the rows.
#include "render/pass_plan.hpp"

#include "gi/photon_map.hpp"
#include "protocol/occluders/slim.hpp"
#include "render/core_passes.hpp"
#include "render/medium_pass.hpp"
#include "render/passes.hpp"
#include "render/slim_pass.hpp"
#include "render/specular_pass.hpp"
#include "render/volume_grid.hpp"
#include "render/volume_pass.hpp"

namespace beamcast {

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

const std::vector<PassDecl>& pass_catalog() {
  using T = TargetId;
  using U = UploadGroup;
  // Each row: name, when it runs, reads, optional reads, writes, uploads,
  // executor.
  static const std::vector<PassDecl> kCatalog = {
      // Occluders lit by the directional light: shaded colour, the view depth
      // of the nearest surface, depth.
      {"surfaces",
       [](const PlanInput& in) { return !in.scene.occluders.empty() && !in.scene.has_gi(); }, {}, {},
       {T::kHdr, T::kViewDepth, T::kDepth}, {U::kOccluders}, [] { return make_surface_pass(false); }},
      // Occluders of a lit scene (scene lights): the same draws into a
      // G-buffer (view depth, normal, albedo and material); hdr gets what
      // the surfaces emit (nothing yet) in place of the background.
      {"gbuffer",
       [](const PlanInput& in) { return !in.scene.occluders.empty() && in.scene.has_gi(); }, {}, {},
       {T::kHdr, T::kViewDepth, T::kGbNormal, T::kGbAlbedo, T::kDepth}, {U::kOccluders}, [] { return make_surface_pass(true); }},
      // SLIM surfaces (seed 003; render/slim_pass.cpp): points sampled on each
      // support sphere's local height field, drawn three times: the nearest
      // point per pixel, the weighted sums of the points within the depth
      // threshold behind it, and their normalization into the surfaces'
      // targets (before the lighting passes, which shade them like any
      // occluder). Points behind a nearer occluder are dropped.
      {"slim_depth", [](const PlanInput& in) { return has_slim(in.scene); },
       {T::kViewDepth}, {}, {T::kSlimNear, T::kSlimRadius}, {U::kSlim}, make_slim_depth_pass},
      {"slim_accumulate",
       [](const PlanInput& in) { return has_slim(in.scene); },
       {T::kViewDepth, T::kSlimNear, T::kSlimRadius}, {},
       {T::kSlimSumAlbedo, T::kSlimSumField, T::kSlimSumWeight, T::kSlimSumField2,
        T::kSlimSumWeight2, T::kSlimZbuf},
       {U::kSlim}, make_slim_accumulate_pass},
      {"slim_resolve",
       [](const PlanInput& in) { return has_slim(in.scene) && !in.scene.has_gi(); },
       {T::kSlimSumAlbedo, T::kSlimSumField, T::kSlimSumWeight, T::kSlimNear,
        T::kSlimSumField2, T::kSlimSumWeight2, T::kSlimRadius},
       {},
       {T::kHdr, T::kViewDepth, T::kSlimSurface}, {}, [] { return make_slim_resolve_pass(false); }},
      {"slim_gbuffer",
       [](const PlanInput& in) { return has_slim(in.scene) && in.scene.has_gi(); },
       {T::kSlimSumAlbedo, T::kSlimSumField, T::kSlimSumWeight, T::kSlimNear,
        T::kSlimSumField2, T::kSlimSumWeight2, T::kSlimRadius},
       {},
       {T::kHdr, T::kViewDepth, T::kSlimSurface, T::kGbNormal, T::kGbAlbedo}, {}, [] { return make_slim_resolve_pass(true); }},
      // Direct light of a lit scene (gi.direct "shadow_maps"): every light as
      // a few point emitters (DirectPoint), each with a cube shadow map of
      // the triangles (rendered once per scene and kept) and shadow rays to
      // the analytic occluders; adds what diffuse surfaces reflect to hdr.
      {"direct",
       [](const PlanInput& in) {
         return shadow_mapped_direct(in.scene) && !interleaves_direct(in.scene);
       },
       {T::kHdr, T::kViewDepth, T::kGbNormal, T::kGbAlbedo}, {}, {T::kHdr}, {U::kShadows}, [] { return make_direct_pass(false); }},
      // The same with gi.direct_interleave 4 (interleaved sampling): each
      // pixel sums a quarter of each interleaved light's points (by its
      // place in a 2 x 2 pattern) into direct_split, the other lights' points
      // into hdr as above; gi_resolve then averages the four quarters
      // over each pixel's 3 x 3 neighbours on its own surface.
      {"direct",
       [](const PlanInput& in) {
         return shadow_mapped_direct(in.scene) && interleaves_direct(in.scene);
       },
       {T::kHdr, T::kViewDepth, T::kGbNormal, T::kGbAlbedo}, {}, {T::kHdr, T::kDirectSplit}, {U::kShadows}, [] { return make_direct_pass(true); }},
      // Photon splatting (seed 001, section 4.2): one camera-facing disk per
      // photon adds its reflected radiance to the G-buffer's pixels within
      // the radius (without the photons straight from a light when the
      // direct pass carries that light).
      {"photons",
       [](const PlanInput& in) { return !in.scene.occluders.empty() && in.scene.has_gi(); },
       {T::kViewDepth, T::kGbNormal, T::kGbAlbedo}, {}, {T::kGiIndirect}, {U::kPhotons}, make_photon_pass},
      // The splats' sum to hdr, divided by the share of each pixel's disk
      // that its surface covers (found in the G-buffer), so a surface's
      // edges and the room's corners are not darkened by the disk hanging
      // over them (gi.edge_correction; shaders/gi_resolve.frag). With the
      // interleaved direct light (direct_split written) the same pass
      // brings its four quarters together (shaders/direct_filter.glsl).
      {"gi_resolve",
       [](const PlanInput& in) { return !in.scene.occluders.empty() && in.scene.has_gi(); },
       {T::kHdr, T::kGiIndirect, T::kViewDepth, T::kGbNormal, T::kGbAlbedo}, {T::kDirectSplit}, {T::kHdr},
       {}, make_gi_resolve_pass},
      // Mirror and glass pixels of a lit scene: the CPU follows their centre
      // rays to what they reach and the radiance there is added to hdr
      // (render/specular_pass.hpp).
      {"specular",
       [](const PlanInput& in) { return in.scene.has_gi() && has_specular(in.scene); },
       {T::kHdr, T::kGbAlbedo, T::kSpecular}, {}, {T::kHdr}, {U::kSpecular}, make_specular_pass},
      // A medium filling the scene (render/medium_pass.hpp): what reached
      // hdr so far (surfaces, background) attenuated by the distance to it;
      // the beams attenuate their own light.
      {"medium", [](const PlanInput& in) { return in.scene.has_medium(); },
       {T::kHdr}, {T::kViewDepth}, {T::kHdr}, {}, make_medium_pass},
      // Light the medium scatters towards the eye in a lit scene: the volume
      // photons (the global map's scattering events), each a camera-facing
      // quad over its kernel, added to hdr up to the nearest surface
      // (render/medium_pass.hpp; medium.estimator picks the estimate).
      {"volume_photons",
       [](const PlanInput& in) {
         return in.scene.has_gi() && in.scene.medium_scatters() && !grid_estimate(in.scene);
       },
       {T::kHdr}, {T::kViewDepth}, {T::kHdr}, {U::kVolumePhotons}, make_volume_photon_pass},
      // The same light without splats (medium.estimator "grid", the
      // default; render/volume_grid.hpp): the volume photons binned into a
      // world grid each frame (compute), each pixel's ray marched through it.
      {"volume_grid",
       [](const PlanInput& in) {
         return in.scene.has_gi() && in.scene.medium_scatters() && grid_estimate(in.scene);
       },
       {T::kHdr}, {T::kViewDepth}, {T::kHdr}, {U::kVolumeGrid}, make_volume_grid_pass},
      // Scalar volumes (seed 004; render/volume_pass.hpp): each ray cast up
      // to the nearest surface and composited over hdr, farther volumes
      // first; with beams in the scene, the same pass also writes the
      // transmittance knots they read (two float targets cleared and
      // blended: 12 ms of a 512^2 frame on llvmpipe, not paid without beams).
      {"volumes",
       [](const PlanInput& in) { return !in.scene.volumes.empty() && in.scene.beams.empty(); },
       {T::kHdr}, {T::kViewDepth}, {T::kHdr}, {U::kVolumes}, [] { return make_volume_pass(false); }},
      {"volumes",
       [](const PlanInput& in) { return !in.scene.volumes.empty() && !in.scene.beams.empty(); },
       {T::kHdr}, {T::kViewDepth}, {T::kHdr, T::kVolumeT0, T::kVolumeT1}, {U::kVolumes}, [] { return make_volume_pass(true); }},
      // Beams: energy added to hdr; a ray ends at the nearest surface if
      // anything wrote view_depth.
      {"beams", [](const PlanInput& in) { return !in.scene.beams.empty(); },
       {T::kHdr}, {T::kViewDepth, T::kVolumeT0, T::kVolumeT1}, {T::kHdr}, {U::kBeams}, make_beam_pass},
      // Every frame is tone-mapped into its output format.
      {"tonemap", [](const PlanInput&) { return true; }, {T::kHdr}, {}, {T::kOutput},
       {}, make_tonemap_pass},
      // Scaled frames (interactive preview): bilinear blit to the camera's size.
      {"upscale", [](const PlanInput& in) { return in.scaled(); }, {T::kOutput}, {},
       {T::kUpscaled}, {}, make_upscale_pass},
  };
  return kCatalog;
}


std::vector<std::string> plan_passes(const Scene& scene, double resolution_scale) {
  return make_plan(PlanInput{scene, resolution_scale}).names();
}

}  // namespace beamcast
