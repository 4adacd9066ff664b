#include "protocol/request_cost.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace beamcast {
namespace {

bool any_specular(const Scene& scene) {
  return std::any_of(scene.occluders.begin(), scene.occluders.end(), [](const Occluder& o) {
    return o.material.type != MaterialType::kDiffuse;
  });
}

// Direct points the direct pass loops over per pixel: a quarter of a light's
// when they are interleaved (render/pass_plan.hpp, interleaves_direct_points).
double direct_points_per_pixel(const Scene& scene) {
  if (scene.occluders.empty() || scene.gi.direct != DirectLightMethod::kShadowMaps) return 0.0;
  double points = 0.0;
  for (const Light& l : scene.lights) {
    const std::size_t n = std::visit(
        [&](const auto& kind) { return kind.direct_points(scene.gi.direct_samples).size(); },
        l.shape);
    const bool split = scene.gi.direct_interleave == 4 && n > 0 && n % 4 == 0;
    points += split ? n / 4.0 : static_cast<double>(n);
  }
  return points;
}

// Steps of a ray along a volume's whole diagonal: the step is the smallest
// spacing x 2^level / samples_per_voxel (render/volume_pass.cpp).
double volume_diagonal_steps(const Volume& v, const VolumeSettings& s) {
  if (!v.grid) return 0.0;
  double d2 = 0.0;
  double smallest = INFINITY;
  for (int a = 0; a < 3; ++a) {
    const double side = (v.grid->dims[a] - 1) * v.spacing[a];
    d2 += side * side;
    smallest = std::min(smallest, std::abs(v.spacing[a]));
  }
  const double step = smallest * std::ldexp(1.0, s.level) / s.samples_per_voxel;
  if (!(step > 0.0)) return INFINITY;  // refused: no march can end
  return std::ceil(std::sqrt(d2) / step) + 1.0;
}

}  // namespace

const CostTerm* RequestCost::dominant() const {
  const auto it = std::max_element(terms.begin(), terms.end(), [](const CostTerm& a, const CostTerm& b) {
    return a.cost < b.cost;
  });
  return it == terms.end() ? nullptr : &*it;
}

std::string RequestCost::breakdown() const {
  std::vector<const CostTerm*> sorted;
  for (const CostTerm& t : terms) sorted.push_back(&t);
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const CostTerm* a, const CostTerm* b) { return a->cost > b->cost; });
  std::string out;
  for (const CostTerm* t : sorted) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s%.*s %.4g", out.empty() ? "" : " + ",
                  static_cast<int>(t->name.size()), t->name.data(), t->cost);
    out += buf;
  }
  return out;
}

RequestCost estimate_request_cost(const Scene& scene, const std::vector<Camera>& cameras,
                                  const CostWeights& w) {
  RequestCost rc;
  const auto add = [&rc](std::string_view name, double units, double weight, std::string path) {
    if (!(units > 0.0)) return;
    const double cost = units * weight;
    rc.terms.push_back({name, units, weight, cost, std::move(path)});
    rc.total += cost;
  };
  const double ss = scene.output.supersample;
  double pixels = 0.0;
  for (const Camera& c : cameras) pixels += static_cast<double>(c.width) * c.height * ss * ss;
  const double views = static_cast<double>(cameras.size());

  add("request", 1.0, w.fixed, "");
  add("pixels", pixels, w.pixel, "/cameras");
  add("beam_pixels", static_cast<double>(scene.beams.size()) * pixels, w.beam_pixel, "/beams");
  // The medium's parts: the scene-wide medium, each region and each
  // mesh-region triangle (optical depth is evaluated over all of them).
  double medium_parts = 0.0;
  if (scene.has_medium()) {
    medium_parts = 1.0;
    for (const MediumRegion& r : scene.media) medium_parts += 1.0 + r.gpu_triangles().size();
  }
  if (scene.has_gi()) {
    add("lit_pixels", pixels, w.lit_pixel, "/cameras");
    add("direct_point_pixels", pixels * direct_points_per_pixel(scene), w.direct_point_pixel,
        "/gi/direct_samples");
    const bool specular = any_specular(scene);
    const double depth = scene.gi.max_depth;
    const double photons = static_cast<double>(scene.gi.photons);
    const double caustic = specular ? static_cast<double>(scene.gi.caustic_photons) : 0.0;
    if (scene.medium_scatters()) {
      // Every event may scatter and be stored; each is splatted per view,
      // its kernel growing with the view's pixels, its optical depth
      // through every medium part.
      add("medium_photon_events", photons * depth, w.medium_photon_event, "/gi/photons");
      double view_scale = 0.0;
      for (const Camera& c : cameras) {
        view_scale += std::max(1.0, static_cast<double>(c.width) * c.height * ss * ss / 262144.0);
      }
      add("volume_photon_views", photons * depth * view_scale * medium_parts,
          w.volume_photon_view, "/gi/photons");
    } else {
      add("photon_bounces", photons * depth, w.photon_bounce, "/gi/photons");
    }
    add("caustic_photon_bounces", caustic * depth, w.photon_bounce, "/gi/caustic_photons");
    if (specular) {
      // The CPU gather at each ray's end visits the photons within the
      // radius, which shrinks as photons^(-1/6): their count grows as
      // photons^(2/3) (1 at the defaults, 1e5 + 1e5).
      const double gather = std::pow(std::max(1.0, (photons + caustic) / 2e5), 2.0 / 3.0);
      add("specular_rays",
          pixels * scene.gi.specular_samples * scene.gi.specular_samples * gather,
          w.specular_ray, "/gi/specular_samples");
    }
  }
  for (std::size_t i = 0; i < scene.volumes.size(); ++i) {
    add("volume_samples", pixels * volume_diagonal_steps(scene.volumes[i], scene.volume),
        w.volume_sample, "/volumes/" + std::to_string(i) + "/spacing");
  }
  double spheres = 0.0, triangles = 0.0;
  for (const Occluder& o : scene.occluders) {
    if (const auto* s = std::get_if<SlimOccluder>(&o.shape)) spheres += s->spheres().size();
    if (const auto* m = std::get_if<MeshOccluder>(&o.shape)) triangles += m->triangles.size();
  }
  const bool patch = scene.slim.evaluation == SlimEvaluation::kPatch;
  add(patch ? "slim_sphere_views" : "slim_sampled_sphere_views", spheres * views,
      patch ? w.slim_sphere_view : w.slim_sampled_sphere_view, "/occluders");
  add("triangle_views", triangles * views, w.triangle_view, "/occluders");
  add("medium_pixels", pixels * medium_parts, w.medium_pixel,
      scene.media.empty() ? "/medium" : "/media");
  return rc;
}

}  // namespace beamcast
