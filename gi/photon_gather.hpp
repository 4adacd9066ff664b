// Radiance estimates from photon maps on the CPU, in double (issue 14,
// item 5): the GPU's fixed-radius splatting estimator evaluated exactly (so
// the splatting's own error is separated from the photons' noise), and the
// textbook k-nearest-neighbour estimator L = (albedo / pi) sum P / (pi r_k^2)
// over a kd-tree (nanoflann).
#pragma once

#include <memory>
#include <vector>

#include "gi/gi_scene.hpp"
#include "gi/photon_map.hpp"
#include "protocol/hdr_image.hpp"

namespace beamcast {

// The splat tests of shaders/photon_splat.frag: a photon lights a point
// whose normal is within acos(min_cos) of its own and that lies within
// max_plane x radius of its plane.
struct SplatTests {
  double min_cos = 0.906;
  double max_plane = 0.1;
};

// The kernel's weight at distance d < r, normalized over the disk of radius r.
double splat_kernel(SplatKernel kernel, double d, double r);

class PhotonGather {
 public:
  // skip_direct: leave out the photons straight from a light (a scene whose
  // direct light comes from the direct pass, gi.direct "shadow_maps").
  explicit PhotonGather(const PhotonMaps& maps, bool skip_direct = false);
  ~PhotonGather();
  // Fixed radii with `kernel`: what the splat pass computes at x (the
  // global map's photons within radii.global, the caustic map's within
  // radii.caustic).
  Color fixed_radius(const Vec3& x, const Vec3& n, const Color& albedo, const SplatRadii& radii,
                     SplatKernel kernel, const SplatTests& tests = {}) const;
  // The k nearest photons (with the normal test), r = the k-th distance.
  Color nearest(const Vec3& x, const Vec3& n, const Color& albedo, int k,
                const SplatTests& tests = {}) const;

 private:
  struct Index;
  std::vector<Photon> photons_;  // the global map's, then the caustic map's
  // Trees over photons_: all of them (nearest), the global and the caustic
  // map's (fixed radius, each map with its own radius).
  std::unique_ptr<Index> index_, global_index_, caustic_index_;
  Color within(const Index& index, const Vec3& x, const Vec3& n, double r, SplatKernel kernel,
               const SplatTests& tests) const;
};

enum class GatherMethod { kFixedRadius, kNearest };

// What a lit frame shows along a ray, on the CPU in double: diffuse surfaces
// the photon estimate (and, with gi.direct "shadow_maps", the direct pass's
// term with exact visibility), quad lights seen from the front their
// radiance, the background where nothing is hit; mirrors their reflectance
// times what the reflected ray shows, glass the Fresnel-weighted sum of the
// reflected and the refracted ray (times the tint per crossing), both
// followed, up to kMaxSpecularDepth specular bounces (then black) and while
// a branch's weight is at least 1e-3. The renderer's "specular" pass shows
// mirror and glass pixels with it (issue 14, item 4).
class LitShading {
 public:
  static constexpr int kMaxSpecularDepth = 8;
  // `gather` must have been built with skip_direct when gi.direct is
  // "shadow_maps". Both must outlive this.
  LitShading(const Scene& scene, const GiScene& surfaces, const PhotonGather& gather,
             GatherMethod method = GatherMethod::kFixedRadius, int k = 50);
  Color trace(const Vec3& o, const Vec3& d, double t_min, double t_max) const;

 private:
  struct FluxPoint {
    DirectPoint point;
    Color flux;
  };
  Color trace(const Vec3& o, const Vec3& d, double t_min, double t_max, int depth,
              double weight) const;
  // What the ray along d sees at `hit` (none: the background).
  Color shade(const std::optional<SurfaceHit>& hit, const Vec3& d, int depth,
              double weight) const;
  Color diffuse(const Vec3& p, const Vec3& n, const Color& albedo) const;
  const Scene& scene_;
  const GiScene& surfaces_;
  const PhotonGather& gather_;
  GatherMethod method_;
  int k_;
  SplatRadii radii_;
  std::vector<FluxPoint> direct_;
};

struct GatherImageOptions {
  GatherMethod method = GatherMethod::kFixedRadius;
  int k = 50;  // kNearest
  int threads = 0;
};

// A lit scene's image (rows top-down, like render_reference): LitShading
// along each pixel's centre ray. With gi.direct "shadow_maps" the direct
// term comes from the same DirectPoints as the GPU's, with visibility by
// shadow rays in double (so the GPU's difference is the shadow maps' error);
// `gather` must then have been built with skip_direct.
HdrImage gather_image(const Scene& scene, const GiScene& surfaces, const PhotonGather& gather,
                      const Camera& cam, const GatherImageOptions& opts = {});

}  // namespace beamcast
