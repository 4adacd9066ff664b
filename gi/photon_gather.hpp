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
#include "render/image.hpp"

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

struct GatherImageOptions {
  GatherMethod method = GatherMethod::kFixedRadius;
  int k = 50;  // kNearest
  int threads = 0;
};

// A lit scene's image (rows top-down, like render_reference): the nearest
// surface along each pixel's centre ray; diffuse surfaces get the photon
// estimate, quad lights their radiance, mirrors and glass and the background
// as the GPU draws them. With gi.direct "shadow_maps" diffuse surfaces also
// get the direct pass's term from the same DirectPoints, with visibility by
// shadow rays in double (so the GPU's difference is the shadow maps' error);
// `gather` must then have been built with skip_direct.
HdrImage gather_image(const Scene& scene, const GiScene& surfaces, const PhotonGather& gather,
                      const Camera& cam, const GatherImageOptions& opts = {});

}  // namespace beamcast
