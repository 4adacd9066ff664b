#include "gi/photon_cache.hpp"

#include <algorithm>
#include <cstring>
#include <functional>
#include <string_view>
#include <type_traits>
#include <variant>

#include "gi/gi_scene.hpp"

namespace beamcast {
namespace {

// Appends the bytes of values; hashed at the end.
class KeyWriter final : public TriangleSink {
 public:
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const char*>(&v);
    bytes_.append(p, sizeof(T));
  }
  void add(const Vec3& a, const Vec3& b, const Vec3& c, bool one_sided) override {
    put(a);
    put(b);
    put(c);
    put(one_sided);
  }
  void text(std::string_view s) { bytes_.append(s); }
  std::string digest() const {
    // 64-bit hash and length: a false match needs a collision of both.
    const std::size_t h = std::hash<std::string_view>{}(bytes_);
    return std::to_string(h) + ":" + std::to_string(bytes_.size());
  }

 private:
  std::string bytes_;
};

}  // namespace

std::string photon_key(const Scene& scene) {
  KeyWriter k;
  for (const Occluder& o : scene.occluders) {
    k.put(o.shape.index());
    k.put(o.albedo);
    k.put(o.material.type);
    k.put(o.material.reflectance);
    k.put(o.material.ior);
    k.put(o.material.tint);
    std::visit(
        [&](const auto& kind) {
          using Kind = std::decay_t<decltype(kind)>;
          if constexpr (Kind::kGpu == GpuForm::kTriangles) {
            kind.gpu_triangles(k);
          } else if constexpr (Kind::kGpu == GpuForm::kAnalytic) {
            const AnalyticGpu g = kind.analytic(Vec3{0.0, 0.0, 0.0});
            k.put(g.a);
            k.put(g.b);
          } else {
            static_assert(std::is_same_v<Kind, SlimOccluder>, "an occluder kind missing from photon_key");
            k.put(kind.spheres().size());
            for (const SlimSphere& s : kind.spheres()) {
              k.put(s.center);
              k.put(s.radius);
              k.put(s.rotation);
              k.put(s.poly.c);
              k.put(s.poly2.c);
              k.put(static_cast<int>(s.crease));
            }
          }
        },
        o.shape);
  }
  for (const Light& l : scene.lights) {
    k.put(l.shape.index());
    k.put(l.flux);
    LightKey lk;
    std::visit([&](const auto& kind) { kind.cache_key(lk); }, l.shape);
    k.put(lk.bytes.size());
    k.text(lk.bytes);
  }
  // The settings tracing reads (radius and kernel only shape the splats).
  k.put(scene.gi.photons);
  k.put(scene.gi.caustic_photons);
  k.put(scene.gi.seed);
  k.put(scene.gi.max_depth);
  // The medium: the paths' free flights, absorption and phase (its beam
  // knobs and the volume estimate's settings only shape the frame).
  const Medium* global = scene.global_medium();
  k.put(global != nullptr);
  if (global) {
    k.put(global->sigma_s);
    k.put(global->sigma_a);
    k.put(global->k);
  }
  k.put(scene.media.size());
  for (const MediumRegion& r : scene.media) {
    // The kind and its GPU record (every number of a convex kind's shape),
    // then a mesh's triangles.
    k.put(r.shape.index());
    const RegionGpu g = r.gpu();
    k.put(g.code);
    k.put(g.a);
    k.put(g.b);
    k.put(g.r);
    k.put(r.sigma_s);
    k.put(r.sigma_a);
    k.put(r.k);
    k.put(r.gpu_triangles().size());
    for (const auto& t : r.gpu_triangles()) {
      for (const Vec3& p : t) k.put(p);
    }
  }
  return k.digest();
}

std::shared_ptr<const PhotonMaps> PhotonCache::get(const Scene& scene, bool* traced) {
  const std::string key = photon_key(scene);
  for (auto it = entries_.begin(); it != entries_.end(); ++it) {
    if (it->key == key) {
      entries_.splice(entries_.begin(), entries_, it);
      if (traced) *traced = false;
      return entries_.front().maps;
    }
  }
  std::shared_ptr<const PhotonMaps> maps = offered_ && offered_key_ == key ? offered_ : nullptr;
  if (!maps) maps = std::make_shared<const PhotonMaps>(trace_photons(scene, GiScene(scene)));
  if (traced) *traced = true;
  const std::size_t bytes =
      (maps->global.size() + maps->caustic.size() + maps->volume.size()) * sizeof(Photon);
  // Maps over the whole budget are used for this render and freed after it,
  // not kept (issue 43: fog in a closed sphere stayed resident at 2.7 GB);
  // a later render of the scene traces them again.
  if (bytes > max_bytes_) return maps;
  entries_.push_front({key, maps, bytes, {}, {}});
  bytes_ += bytes;
  // Evict the least recently used, but keep the one just traced (its
  // gather trees and disks, added later, may still take it over the budget).
  while (bytes_ > max_bytes_ && entries_.size() > 1) {
    bytes_ -= entries_.back().bytes;
    entries_.pop_back();
  }
  return maps;
}

bool PhotonCache::holds(const std::string& key) const {
  return std::any_of(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.key == key; });
}

void PhotonCache::shrink_to(std::size_t max_bytes) {
  while (bytes_ > max_bytes && !entries_.empty()) {
    bytes_ -= entries_.back().bytes;
    entries_.pop_back();
  }
}

std::shared_ptr<const PhotonGather> PhotonCache::gather(
    const std::shared_ptr<const PhotonMaps>& maps, bool skip_direct) {
  for (Entry& e : entries_) {
    if (e.maps != maps) continue;
    auto& g = e.gather[skip_direct ? 1 : 0];
    if (!g) {
      g = std::make_shared<const PhotonGather>(*maps, skip_direct);
      // The trees and their copy of the photons count with the maps.
      const std::size_t extra = 2 * (maps->global.size() + maps->caustic.size()) * sizeof(Photon);
      e.bytes += extra;
      bytes_ += extra;
    }
    return g;
  }
  return std::make_shared<const PhotonGather>(*maps, skip_direct);
}

std::shared_ptr<const SplatDiskSet> PhotonCache::disks(const std::shared_ptr<const PhotonMaps>& maps,
                                                       const SplatDiskOptions& options) {
  constexpr std::size_t kKept = 4;
  for (Entry& e : entries_) {
    if (e.maps != maps) continue;
    for (auto it = e.disk_sets.begin(); it != e.disk_sets.end(); ++it) {
      if (it->first == options) {
        e.disk_sets.splice(e.disk_sets.begin(), e.disk_sets, it);
        return e.disk_sets.front().second;
      }
    }
    auto set = std::make_shared<const SplatDiskSet>(splat_disks(*maps, options));
    const std::size_t added = set->disks.size() * sizeof(SplatDisk);
    e.disk_sets.emplace_front(options, set);
    e.bytes += added;
    bytes_ += added;
    if (e.disk_sets.size() > kKept) {
      const std::size_t dropped = e.disk_sets.back().second->disks.size() * sizeof(SplatDisk);
      e.disk_sets.pop_back();
      e.bytes -= dropped;
      bytes_ -= dropped;
    }
    return set;
  }
  return std::make_shared<const SplatDiskSet>(splat_disks(*maps, options));
}

}  // namespace beamcast
