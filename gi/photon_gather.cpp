#include "gi/photon_gather.hpp"

#include <nanoflann.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <thread>
#include <variant>

#include "gi/optics.hpp"
#include "gi/parallel.hpp"
#include "protocol/camera.hpp"

namespace beamcast {

double splat_kernel(SplatKernel kernel, double d, double r) {
  if (!(d < r)) return 0.0;
  const double area = std::numbers::pi * r * r;
  switch (kernel) {
    case SplatKernel::kBox:
      return 1.0 / area;
    case SplatKernel::kCone:
      return 3.0 / area * (1.0 - d / r);
    case SplatKernel::kEpanechnikov:
      return 2.0 / area * (1.0 - (d * d) / (r * r));
  }
  return 0.0;
}

namespace {

// Photons [first, first + count) of one vector: the global map's, the
// caustic map's, or both (nearest), without copies.
struct Cloud {
  const std::vector<Photon>* photons;
  std::size_t first = 0, count = 0;
  std::size_t kdtree_get_point_count() const { return count; }
  float kdtree_get_pt(std::size_t i, std::size_t dim) const { return (*photons)[first + i].p[dim]; }
  const Photon& at(std::size_t i) const { return (*photons)[first + i]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>, Cloud, 3>;

Vec3 pos(const Photon& p) { return {p.p[0], p.p[1], p.p[2]}; }
Vec3 normal(const Photon& p) { return {p.n[0], p.n[1], p.n[2]}; }

bool passes(const Photon& p, const Vec3& x, const Vec3& n, double r, const SplatTests& t) {
  if (dot(normal(p), n) < t.min_cos) return false;
  return std::abs(dot(x - pos(p), n)) <= t.max_plane * r;
}

}  // namespace

struct PhotonGather::Index {
  Cloud cloud;
  Tree tree;
  Index(const std::vector<Photon>* photons, std::size_t first, std::size_t count)
      : cloud{photons, first, count},
        tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {
    tree.buildIndex();
  }
};

PhotonGather::PhotonGather(const PhotonMaps& maps, bool skip_direct) {
  std::size_t global_count = 0;
  for (const auto* map : {&maps.global, &maps.caustic}) {
    for (const Photon& p : *map) {
      if (!skip_direct || p.bounces != 0) photons_.push_back(p);
    }
    if (map == &maps.global) global_count = photons_.size();
  }
  index_ = std::make_unique<Index>(&photons_, 0, photons_.size());
  global_index_ = std::make_unique<Index>(&photons_, 0, global_count);
  caustic_index_ = std::make_unique<Index>(&photons_, global_count, photons_.size() - global_count);
}

PhotonGather::~PhotonGather() = default;

Color PhotonGather::within(const Index& index, const Vec3& x, const Vec3& n, double r,
                           SplatKernel kernel, const SplatTests& tests) const {
  Color sum{0.0, 0.0, 0.0};
  if (index.cloud.count == 0 || !(r > 0.0)) return sum;
  const float q[3] = {static_cast<float>(x[0]), static_cast<float>(x[1]), static_cast<float>(x[2])};
  std::vector<std::pair<std::uint32_t, float>> found;
  nanoflann::SearchParams params;
  params.sorted = false;
  index.tree.radiusSearch(q, static_cast<float>(r * r) * 1.0001f, found, params);
  for (const auto& [i, d2] : found) {
    const Photon& p = index.cloud.at(i);
    const double d = length(x - pos(p));
    const double w = splat_kernel(kernel, d, r);
    if (w == 0.0 || !passes(p, x, n, r, tests)) continue;
    for (int k = 0; k < 3; ++k) sum[k] += w * p.power[k];
  }
  return sum;
}

Color PhotonGather::fixed_radius(const Vec3& x, const Vec3& n, const Color& albedo, const SplatRadii& radii,
                                 SplatKernel kernel, const SplatTests& tests) const {
  const Color sum = within(*global_index_, x, n, radii.global, kernel, tests) +
                    within(*caustic_index_, x, n, radii.caustic, kernel, tests);
  return {albedo[0] / std::numbers::pi * sum[0], albedo[1] / std::numbers::pi * sum[1],
          albedo[2] / std::numbers::pi * sum[2]};
}

Color PhotonGather::nearest(const Vec3& x, const Vec3& n, const Color& albedo, int k,
                            const SplatTests& tests) const {
  if (photons_.empty() || k <= 0) return {0.0, 0.0, 0.0};
  const float q[3] = {static_cast<float>(x[0]), static_cast<float>(x[1]), static_cast<float>(x[2])};
  std::vector<std::uint32_t> idx(static_cast<std::size_t>(k));
  std::vector<float> d2(static_cast<std::size_t>(k));
  const std::size_t found = index_->tree.knnSearch(q, static_cast<std::size_t>(k), idx.data(), d2.data());
  if (found == 0) return {0.0, 0.0, 0.0};
  double r = 0.0;
  for (std::size_t i = 0; i < found; ++i) r = std::max(r, length(x - pos(photons_[idx[i]])));
  if (!(r > 0.0)) return {0.0, 0.0, 0.0};
  Color sum{0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < found; ++i) {
    const Photon& p = photons_[idx[i]];
    if (!passes(p, x, n, r, tests)) continue;
    for (int c = 0; c < 3; ++c) sum[c] += p.power[c];
  }
  const double scale = 1.0 / (std::numbers::pi * std::numbers::pi * r * r);
  return {albedo[0] * scale * sum[0], albedo[1] * scale * sum[1], albedo[2] * scale * sum[2]};
}

LitShading::LitShading(const Scene& scene, const GiScene& surfaces, const PhotonGather& gather,
                       GatherMethod method, int k)
    : scene_(scene),
      surfaces_(surfaces),
      gather_(gather),
      method_(method),
      k_(k),
      radii_(splat_radii(scene)) {
  if (scene.gi.direct == DirectLightMethod::kShadowMaps) {
    for (const Light& l : scene.lights) {
      const auto points = std::visit(
          [&](const auto& kind) { return kind.direct_points(scene.gi.direct_samples); }, l.shape);
      for (const DirectPoint& p : points) direct_.push_back({p, l.flux});
    }
  }
}

// The direct pass's sum (shaders/direct_light.frag) with exact visibility,
// plus the photon estimate.
Color LitShading::diffuse(const Vec3& x, const Vec3& n, const Color& albedo) const {
  Color c = method_ == GatherMethod::kFixedRadius
                ? gather_.fixed_radius(x, n, albedo, radii_, scene_.gi.kernel)
                : gather_.nearest(x, n, albedo, k_);
  if (direct_.empty()) return c;
  Color sum{0.0, 0.0, 0.0};
  const double eps = surfaces_.epsilon();
  for (const FluxPoint& fp : direct_) {
    const DirectPoint& p = fp.point;
    const Vec3 to = p.position - x;
    const double d = length(to);
    if (!(d > 2.0 * eps)) continue;
    const Vec3 l = (1.0 / d) * to;
    const double cos_x = dot(n, l);
    if (cos_x <= 0.0) continue;
    const double cl = -dot(p.axis, l);
    double angular = 1.0;
    if (p.mode == DirectPoint::Mode::kCosine) {
      angular = std::max(cl, 0.0);
    } else if (p.mode == DirectPoint::Mode::kCone) {
      if (cl >= p.cos_inner) {
        angular = 1.0;
      } else if (cl <= p.cos_outer) {
        angular = 0.0;
      } else {
        const double t = (cl - p.cos_outer) / (p.cos_inner - p.cos_outer);
        angular = t * t * (3.0 - 2.0 * t);
      }
    }
    if (angular <= 0.0 || surfaces_.occluded(x, l, eps, d - eps)) continue;
    const double g = p.scale * angular * cos_x / (d * d);
    for (std::size_t k = 0; k < 3; ++k) sum[k] += g * fp.flux[k];
  }
  for (std::size_t k = 0; k < 3; ++k) c[k] += sum[k] * albedo[k] / std::numbers::pi;
  return c;
}

Color LitShading::trace(const Vec3& o, const Vec3& d, double t_min, double t_max) const {
  return trace(o, d, t_min, t_max, 0, 1.0);
}

Color LitShading::trace(const Vec3& o, const Vec3& d, double t_min, double t_max, int depth,
                        double weight) const {
  const auto hit = surfaces_.intersect(o, d, t_min, t_max);
  const Color c = shade(hit, d, depth, weight);
  // Beyond a mirror or through glass (depth > 0) the medium attenuates the
  // segment (the background, at infinity, by the optical depth to it); the
  // camera's own segment is the medium pass's. Light scattered into these
  // segments is not added.
  if (depth == 0 || !scene_.has_medium()) return c;
  // (From the surface the ray leaves, t = 0, not from its t_min offset.)
  const double seen = std::exp(-scene_.medium_field().optical_depth(
      o, d, 0.0, hit ? hit->t : std::numeric_limits<double>::infinity()));
  return seen * c;
}

Color LitShading::shade(const std::optional<SurfaceHit>& hit, const Vec3& d, int depth,
                        double weight) const {
  if (!hit) return scene_.background;
  if (hit->light >= 0) {  // a quad light seen from its front: its radiance
    const Light& l = scene_.lights[static_cast<std::size_t>(hit->light)];
    const double scale = std::visit([](const auto& k) { return k.radiance_scale(); }, l.shape);
    return {scale * l.flux[0], scale * l.flux[1], scale * l.flux[2]};
  }
  if (hit->occluder < 0) return {0.0, 0.0, 0.0};
  const Occluder& occ = scene_.occluders[static_cast<std::size_t>(hit->occluder)];
  const Material& m = occ.material;
  if (m.type == MaterialType::kDiffuse) return diffuse(hit->p, hit->n, occ.albedo);
  if (depth >= kMaxSpecularDepth || weight < 1e-3) return {0.0, 0.0, 0.0};
  const double eps = surfaces_.epsilon();
  const Vec3& n = hit->n;
  auto follow = [&](const Vec3& v, double w) {
    return trace(hit->p, v, eps, std::numeric_limits<double>::infinity(), depth + 1, weight * w);
  };
  if (m.type == MaterialType::kMirror) {
    const double w = std::max({m.reflectance[0], m.reflectance[1], m.reflectance[2]});
    return mul(m.reflectance, follow(reflect(d, n), w));
  }
  // Glass (the outside is vacuum; `entering` says which side the ray came
  // from): F of the reflected ray, 1 - F of the refracted one times the
  // tint of this crossing; radiance's (eta_t / eta_i)^2 cancels over a path
  // that starts and ends outside (as in the path tracer).
  const double eta_i = hit->entering ? 1.0 : m.ior;
  const double eta_t = hit->entering ? m.ior : 1.0;
  const double F = fresnel_dielectric(-dot(d, n), eta_i, eta_t);
  Color c = F > 0.0 ? F * follow(reflect(d, n), F) : Color{0.0, 0.0, 0.0};
  if (F < 1.0) {
    if (const std::optional<Vec3> t = refract(d, n, eta_i, eta_t)) {
      const double tw = std::max({m.tint[0], m.tint[1], m.tint[2]});
      c = c + (1.0 - F) * mul(m.tint, follow(normalize(*t), (1.0 - F) * tw));
    }
  }
  return c;
}

HdrImage gather_image(const Scene& scene, const GiScene& surfaces, const PhotonGather& gather,
                      const Camera& cam, const GatherImageOptions& opts) {
  const LitShading shading(scene, surfaces, gather, opts.method, opts.k);
  HdrImage img;
  img.width = cam.width;
  img.height = cam.height;
  img.rgb.assign(3 * static_cast<std::size_t>(cam.width) * cam.height, 0.0f);
  const CameraBasis basis = camera_basis(cam);
  auto row = [&](int y) {
    const int py = cam.height - 1 - y;  // GL pixel rows count from the bottom
    for (int x = 0; x < cam.width; ++x) {
      check_cancel();  // a pixel's gather follows specular paths: rows can take long
      const Ray ray = camera_ray(cam, basis, x, py);
      const Color c = shading.trace(ray.origin, ray.dir, ray.t_min, ray.t_max);
      float* px = img.at(x, y);
      for (int k = 0; k < 3; ++k) px[k] = static_cast<float>(c[k]);
    }
  };
  parallel_items(cam.height, opts.threads, row);
  return img;
}

}  // namespace beamcast
