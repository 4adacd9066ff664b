#include "gi/photon_clusters.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace beamcast {
namespace {

// The splat's plane test (render/passes.cpp kSplatMaxPlane): surfaces
// further apart than this share of the radius are told apart.
constexpr double kPlaneFraction = 0.1;

struct Key {
  std::int32_t cell[3];
  std::int32_t plane;
  std::int16_t normal_bin;
  std::int16_t direct;
  bool operator==(const Key& o) const {
    return cell[0] == o.cell[0] && cell[1] == o.cell[1] && cell[2] == o.cell[2] &&
           plane == o.plane && normal_bin == o.normal_bin && direct == o.direct;
  }
};

struct KeyHash {
  std::size_t operator()(const Key& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (const std::int64_t v : {std::int64_t{k.cell[0]}, std::int64_t{k.cell[1]},
                                 std::int64_t{k.cell[2]}, std::int64_t{k.plane},
                                 std::int64_t{k.normal_bin}, std::int64_t{k.direct}}) {
      h = (h ^ static_cast<std::uint64_t>(v)) * 1099511628211ull;
    }
    return static_cast<std::size_t>(h);
  }
};

struct Sum {
  std::size_t first = 0;  // index of its first photon
  double weight = 0.0;    // sum of the photons' scalar power
  std::array<double, 3> power{};
  std::array<double, 3> moment1{};  // sum w p
  std::array<double, 3> normal{};   // sum w n
};

// A normal's bin: its dominant axis and sign (6), then 4 x 4 over that
// cube face: normals in one bin are within about 20 degrees.
std::int16_t normal_bin(const float n[3]) {
  int axis = 0;
  for (int k = 1; k < 3; ++k) {
    if (std::abs(n[k]) > std::abs(n[axis])) axis = k;
  }
  const double major = std::abs(static_cast<double>(n[axis]));
  if (major == 0.0) return 0;  // volume photons have none; all in one bin
  auto sub = [&](int k) {
    const double t = static_cast<double>(n[k]) / major;  // in [-1, 1]
    return std::clamp(static_cast<int>(std::floor((t + 1.0) * 2.0)), 0, 3);
  };
  const int u = sub((axis + 1) % 3);
  const int v = sub((axis + 2) % 3);
  const int face = axis * 2 + (n[axis] < 0.0f ? 1 : 0);
  return static_cast<std::int16_t>(face * 16 + u * 4 + v);
}

std::int32_t cell_of(double x, double size) {
  const double c = std::floor(x / size);
  return static_cast<std::int32_t>(std::clamp(c, -2.0e9, 2.0e9));
}

SplatDisk disk_of(const Photon& p, const Vec3& anchor, double power_scale) {
  SplatDisk d{};
  for (std::size_t k = 0; k < 3; ++k) {
    d.position[k] = static_cast<float>(p.p[k] - anchor[k]);
    d.power[k] = static_cast<float>(p.power[k] * power_scale);
    d.normal[k] = p.n[k];
  }
  d.position[3] = p.bounces == 0 ? 1.0f : 0.0f;
  return d;
}

}  // namespace

std::vector<SplatDisk> cluster_photons(const std::vector<Photon>& photons, std::size_t count,
                                       bool skip_direct, const Vec3& anchor,
                                       const ClusterOptions& options) {
  // photons[0, end) holds the `count` photons drawn.
  std::size_t end = 0;
  for (std::size_t kept = 0; end < photons.size() && kept < count; ++end) {
    if (!(skip_direct && photons[end].bounces == 0)) ++kept;
  }
  std::vector<SplatDisk> out;
  const double cell = options.cell_fraction * options.radius;
  if (!(cell > 0.0)) {
    out.reserve(count);
    for (std::size_t i = 0; i < end; ++i) {
      if (skip_direct && photons[i].bounces == 0) continue;
      out.push_back(disk_of(photons[i], anchor, options.power_scale));
    }
    return out;
  }
  const double plane = kPlaneFraction * options.radius;
  std::unordered_map<Key, Sum, KeyHash> sums;
  sums.reserve(count / 4 + 16);
  for (std::size_t i = 0; i < end; ++i) {
    const Photon& p = photons[i];
    if (skip_direct && p.bounces == 0) continue;
    std::array<double, 3> rel{};
    double along = 0.0;
    for (std::size_t k = 0; k < 3; ++k) {
      rel[k] = static_cast<double>(p.p[k]) - anchor[k];
      along += rel[k] * static_cast<double>(p.n[k]);
    }
    const Key key{{cell_of(rel[0], cell), cell_of(rel[1], cell), cell_of(rel[2], cell)},
                  cell_of(along, plane),
                  normal_bin(p.n),
                  static_cast<std::int16_t>(p.bounces == 0 ? 1 : 0)};
    auto [it, fresh] = sums.try_emplace(key);
    Sum& s = it->second;
    if (fresh) s.first = i;
    const double w = static_cast<double>(p.power[0]) + p.power[1] + p.power[2];
    s.weight += w;
    for (std::size_t k = 0; k < 3; ++k) {
      s.power[k] += p.power[k];
      s.moment1[k] += w * rel[k];
      s.normal[k] += w * static_cast<double>(p.n[k]);
    }
  }
  std::vector<const Sum*> order;
  order.reserve(sums.size());
  for (const auto& entry : sums) order.push_back(&entry.second);
  std::sort(order.begin(), order.end(), [](const Sum* a, const Sum* b) { return a->first < b->first; });
  out.reserve(order.size());
  for (const Sum* s : order) {
    const Photon& first = photons[s->first];
    if (!(s->weight > 0.0)) {  // powerless photons: as they are
      out.push_back(disk_of(first, anchor, options.power_scale));
      continue;
    }
    SplatDisk d{};
    double n2 = 0.0;
    for (std::size_t k = 0; k < 3; ++k) {
      n2 += s->normal[k] * s->normal[k];
      d.position[k] = static_cast<float>(s->moment1[k] / s->weight);
      d.power[k] = static_cast<float>(s->power[k] * options.power_scale);
    }
    const double n_len = std::sqrt(n2);
    for (std::size_t k = 0; k < 3; ++k) {
      d.normal[k] = n_len > 0.0 ? static_cast<float>(s->normal[k] / n_len) : first.n[k];
    }
    d.position[3] = first.bounces == 0 ? 1.0f : 0.0f;
    out.push_back(d);
  }
  return out;
}

SplatDiskSet splat_disks(const PhotonMaps& maps, const SplatDiskOptions& options) {
  SplatDiskSet set;
  Aabb box;
  for (const auto* map : {&maps.global, &maps.caustic}) {
    for (const Photon& p : *map) box.grow(Vec3{p.p[0], p.p[1], p.p[2]});
  }
  set.anchor = box.empty() ? Vec3{0.0, 0.0, 0.0} : box.centre();
  for (const auto* map : {&maps.global, &maps.caustic}) {
    const bool caustic = map == &maps.caustic;
    if (caustic) set.caustic_first = set.disks.size();
    const auto kept = static_cast<std::size_t>(std::count_if(map->begin(), map->end(), [&](const Photon& p) {
      return !(options.skip_direct && p.bounces == 0);
    }));
    set.photons += static_cast<std::int64_t>(kept);
    const auto drawn = static_cast<std::size_t>(std::llround(options.share * static_cast<double>(kept)));
    const ClusterOptions cluster{caustic ? options.caustic_radius : options.radius, options.cluster,
                                 1.0 / options.share};
    const std::vector<SplatDisk> disks =
        cluster_photons(*map, drawn, options.skip_direct, set.anchor, cluster);
    set.disks.insert(set.disks.end(), disks.begin(), disks.end());
  }
  return set;
}

}  // namespace beamcast
