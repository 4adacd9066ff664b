// Photons merged into clusters before splatting (gi.cluster): the splat
// pass's cost is its fill, one disk per photon, so every pixel is drawn
// over by every photon within the radius (on the Cornell box at 1e5 photons
// about 800 disks a pixel). Photons that share a cell of side
// `cell_fraction` x radius, a normal bin and a plane (within a tenth of the
// radius, the splat's plane test) become one disk at their power-weighted
// centroid with their summed power. Each disk's kernel integrates to its
// power, so the splats' energy is kept; the sum's shape differs from the
// photons' own by their spread about the centroid, s^2 / r^2 of the
// kernel's peak (about 1% at cell_fraction 0.25; inside the disk it is
// exactly that for the Epanechnikov kernel, of the other sign near the
// rim). Correcting the inside by s^2 (tried) loses 2 s^2 / r^2 of the
// energy at the rims and doubled the difference from unmerged photons.
// docs/gi.md, "Photon clusters".
#pragma once

#include <cstddef>
#include <vector>

#include "gi/photon_map.hpp"

namespace beamcast {

// One disk of the splat pass (the layout of shaders/photon_splat.vert's
// PhotonData).
struct SplatDisk {
  float position[4];  // xyz: relative to the anchor; w: 1 if straight from the light
  float power[4];     // rgb: flux; w: 0
  float normal[4];    // xyz: unit normal
};

struct ClusterOptions {
  double radius = 1.0;         // the splat radius of this map
  double cell_fraction = 0.0;  // cell side / radius; 0: every photon its own disk
  double power_scale = 1.0;    // every power times this (1 / the share drawn)
};

// The disks for the first `count` photons that are not, with skip_direct,
// straight from the light, positions relative to `anchor`; in the order of each
// cluster's first photon (storage order: the level of detail's groups
// stay spread over the scene). Deterministic.
std::vector<SplatDisk> cluster_photons(const std::vector<Photon>& photons, std::size_t count,
                                       bool skip_direct, const Vec3& anchor,
                                       const ClusterOptions& options);

// What the splat pass uploads for a scene's maps: both maps' disks (the
// global map's, then the caustic map's from caustic_first), relative to
// the photons' centre `anchor`.
struct SplatDiskSet {
  Vec3 anchor{};
  std::vector<SplatDisk> disks;
  std::size_t caustic_first = 0;
  std::int64_t photons = 0;  // the photons they hold (before the drawn share)
};

struct SplatDiskOptions {
  bool skip_direct = false;     // leave out photons straight from the lights
  double share = 1.0;           // the drawn share of each map (display_share)
  double radius = 1.0;          // the global map's splat radius
  double caustic_radius = 1.0;  // the caustic map's
  double cluster = 0.0;         // GiSettings::cluster
  bool operator==(const SplatDiskOptions&) const = default;
};

SplatDiskSet splat_disks(const PhotonMaps& maps, const SplatDiskOptions& options);

}  // namespace beamcast
