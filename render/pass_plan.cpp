#include "render/pass_plan.hpp"

#include "gi/photon_map.hpp"

#include <algorithm>

namespace beamcast {

namespace {

template <class T>
bool contains(const std::vector<T>& v, const T& x) {
  return std::find(v.begin(), v.end(), x) != v.end();
}

}  // namespace

bool interleaves_direct_points(const GiSettings& gi, std::size_t points) {
  return gi.direct_interleave == 4 && points > 0 && points % 4 == 0;
}


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
      {TargetId::kHdr, "hdr", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kBackground},
      {TargetId::kViewDepth, "view_depth", TargetFormat::kR32f, TargetSize::kRender, TargetClear::kNoSurface},
      {TargetId::kDepth, "depth", TargetFormat::kDepth32f, TargetSize::kRender, TargetClear::kFarDepth},
      {TargetId::kOutput, "output", TargetFormat::kDisplay, TargetSize::kRender, TargetClear::kNone},
      {TargetId::kUpscaled, "upscaled", TargetFormat::kDisplay, TargetSize::kCamera, TargetClear::kNone},
      // G-buffer of lit (global illumination) scenes: the surface normal
      // facing the camera, and albedo with the material code (w).
      {TargetId::kGbNormal, "gb_normal", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kNone},
      {TargetId::kGbAlbedo, "gb_albedo", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kNone},
      // What the photon splats add up, before the edge correction (gi_resolve).
      // At gi.splat_scale times fewer pixels per side (indirect light is smooth).
      {TargetId::kGiIndirect, "gi_indirect", TargetFormat::kRgba32f, TargetSize::kSplat, TargetClear::kZero},
      // SLIM point sampling (render/slim_pass.cpp): the nearest view depth
      // per pixel (field evaluation: on the pixel's centre ray, with the
      // smallest owning sphere's radius), then the sums of what lies within
      // the depth threshold behind it: blend (the seed's) (w n, w) and
      // (w albedo, w view depth); field F's terms at two points of the
      // centre ray, (w grad h + h grad w, w h) and (grad w, w), and
      // (w albedo, -). The slim passes clear these themselves, over the
      // surfaces' pixel bounds only (render/slim_pass.cpp). The resolved
      // surface: (unit normal, view depth), zero where none.
      {TargetId::kSlimNear, "slim_near", TargetFormat::kR32f, TargetSize::kRender, TargetClear::kNone},
      {TargetId::kSlimRadius, "slim_radius", TargetFormat::kR32f, TargetSize::kRender, TargetClear::kNone},
      // slim.evaluation "patch": slim_near as a depth buffer, which culls
      // the accumulate pass's hidden patches before their fragments run
      // (written over the surfaces' pixel bounds before each use; outside
      // them no patch can be, so it is never cleared).
      {TargetId::kSlimZbuf, "slim_zbuf", TargetFormat::kDepth32f, TargetSize::kRender, TargetClear::kNone},
      {TargetId::kSlimSumAlbedo, "slim_sum_albedo", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kNone},
      {TargetId::kSlimSumField, "slim_sum_field", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kNone},
      {TargetId::kSlimSumWeight, "slim_sum_weight", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kNone},
      {TargetId::kSlimSumField2, "slim_sum_field2", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kNone},
      {TargetId::kSlimSumWeight2, "slim_sum_weight2", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kNone},
      {TargetId::kSlimSurface, "slim_surface", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kZero},
      // The volumes' transmittance along each pixel's ray, for the beams
      // behind and inside them (shaders/volume_knots.glsl): the ray's
      // interval in the box around all volumes cut into 7 equal segments,
      // the transmittance at each one's middle (volume_t0: segments 0-3,
      // volume_t1: 4-6) and at the interval's end (volume_t1.w); products
      // over the volumes, so cleared to one.
      {TargetId::kVolumeT0, "volume_t0", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kOne},
      {TargetId::kVolumeT1, "volume_t1", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kOne},
      // The interleaved direct points' irradiance, each pixel's quarter at 4
      // times the weight (w: the view depth where a diffuse surface was lit, else 0), before the
      // gi_resolve pass brings the four quarters together.
      {TargetId::kDirectSplit, "direct_split", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kZero},
      // What mirror and glass pixels show, found on the CPU (render/specular_pass.hpp).
      {TargetId::kSpecular, "specular", TargetFormat::kRgba32f, TargetSize::kRender, TargetClear::kZero},
  };
  return kTargets;
}

const char* upload_group_name(UploadGroup g) {
  switch (g) {
    case UploadGroup::kBeams: return "beams";
    case UploadGroup::kOccluders: return "occluders";
    case UploadGroup::kPhotons: return "photons";
    case UploadGroup::kVolumePhotons: return "volume_photons";
    case UploadGroup::kVolumeGrid: return "volume_grid";
    case UploadGroup::kShadows: return "shadows";
    case UploadGroup::kSlim: return "slim";
    case UploadGroup::kVolumes: return "volumes";
    case UploadGroup::kSpecular: return "specular";
  }
  return "?";
}

bool FramePlan::written(TargetId target) const {
  return std::any_of(passes.begin(), passes.end(),
                     [&](const PassDecl* p) { return contains(p->writes, target); });
}

bool FramePlan::uses(TargetId target) const {
  return std::any_of(targets.begin(), targets.end(),
                     [&](const TargetDecl* t) { return t->id == target; });
}

bool FramePlan::uploads_group(UploadGroup group) const { return contains(uploads, group); }

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
  auto target = [&](const PassDecl& pass, TargetId id) -> const TargetDecl* {
    for (const TargetDecl& t : targets) {
      if (t.id == id) return &t;
    }
    throw PlanError("pass \"" + pass.name + "\" names target " +
                    std::to_string(static_cast<int>(id)) + ", which is not in the target catalog");
  };
  auto use = [&](const TargetDecl* t) {
    if (std::find(plan.targets.begin(), plan.targets.end(), t) == plan.targets.end()) {
      plan.targets.push_back(t);
    }
  };
  for (const PassDecl& pass : catalog) {
    if (!pass.needed(in)) continue;
    for (const TargetId r : pass.reads) {
      const TargetDecl* t = target(pass, r);
      if (t->clear == TargetClear::kNone && !plan.written(r)) {
        throw PlanError("pass \"" + pass.name + "\" reads target \"" + t->name +
                        "\", which no earlier planned pass writes and nothing clears");
      }
      use(t);
    }
    for (const TargetId r : pass.optional_reads) {
      const TargetDecl* t = target(pass, r);
      if (plan.written(r)) use(t);
    }
    for (const TargetId w : pass.writes) use(target(pass, w));
    for (const UploadGroup u : pass.uploads) {
      if (!contains(plan.uploads, u)) plan.uploads.push_back(u);
    }
    plan.passes.push_back(&pass);
  }
  if (!plan.passes.empty() && !plan.passes.back()->writes.empty()) {
    plan.final_target = plan.passes.back()->writes.front();
  }
  return plan;
}


}  // namespace beamcast
