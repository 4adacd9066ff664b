// Photon maps kept across renders (issue 14, item 2): keyed by everything the
// tracing depends on (occluder geometry and materials, lights, gi settings)
// and nothing else, so a render that changes only cameras, output or beams
// re-traces nothing. Bounded in bytes; least recently used maps go first,
// and maps larger than the whole budget are not kept at all.
// One per renderer (render thread); not thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <list>
#include <memory>
#include <string>
#include <utility>

#include "gi/photon_gather.hpp"
#include "gi/photon_clusters.hpp"
#include "gi/photon_map.hpp"

namespace beamcast {

// A digest of what photon tracing of `scene` depends on: equal for scenes
// whose maps are equal.
std::string photon_key(const Scene& scene);

class PhotonCache {
 public:
  explicit PhotonCache(std::size_t max_bytes = std::size_t{256} << 20) : max_bytes_(max_bytes) {}
  // The scene's maps, traced now (and kept) unless cached; `traced` tells which.
  // Maps offered for the scene's key (offer) are taken as if traced now.
  std::shared_ptr<const PhotonMaps> get(const Scene& scene, bool* traced = nullptr);
  // Whether maps for this photon_key are kept.
  bool holds(const std::string& key) const;
  // Maps traced elsewhere (another thread: trace_photons over GiScene(scene),
  // the same maps get() would trace) for the scene of `key`: get() takes them
  // in place of tracing, until offer() is called again (null: none).
  void offer(std::string key, std::shared_ptr<const PhotonMaps> maps) {
    offered_key_ = std::move(key);
    offered_ = std::move(maps);
  }
  // The photon search structures over `maps` (which get() returned and
  // which is still cached; else built for this call only), built on first
  // use and kept with the maps: one per skip_direct.
  std::shared_ptr<const PhotonGather> gather(const std::shared_ptr<const PhotonMaps>& maps,
                                             bool skip_direct);
  // The splat pass's disks for `maps` (as for gather()), built on first use
  // and kept with the maps for the 4 most recent options (the preview's
  // photon knob moves the drawn share): a camera-only change clusters
  // nothing again.
  std::shared_ptr<const SplatDiskSet> disks(const std::shared_ptr<const PhotonMaps>& maps,
                                            const SplatDiskOptions& options);
  // Evicts the least recently used maps until at most `max_bytes` are held
  // (the server calls it once its renderer is idle: server/memory.hpp).
  void shrink_to(std::size_t max_bytes);
  std::size_t bytes() const { return bytes_; }
  std::size_t entries() const { return entries_.size(); }

 private:
  struct Entry {
    std::string key;
    std::shared_ptr<const PhotonMaps> maps;
    std::size_t bytes;
    std::shared_ptr<const PhotonGather> gather[2];  // by skip_direct
    // Most recently used first.
    std::list<std::pair<SplatDiskOptions, std::shared_ptr<const SplatDiskSet>>> disk_sets;
  };
  std::size_t max_bytes_;
  std::size_t bytes_ = 0;
  std::list<Entry> entries_;  // most recently used first
  std::string offered_key_;
  std::shared_ptr<const PhotonMaps> offered_;
};

}  // namespace beamcast
