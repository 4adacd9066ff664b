// A renderer's cache of uploads that depend only on a scene's content
// (issue 39): defined in render/scene_resources.cpp.
#pragma once

#include <cstddef>
#include <cstdint>
#include <list>
#include <map>
#include <memory>
#include <string>

namespace beamcast {

// What the renderer uploads from a scene's content alone (occluder
// triangles, SLIM sphere records), kept across renders and stored scenes by
// a key naming that content (SceneResources builds the keys), within a byte
// budget, least recently used evicted first. An entry in use by a render
// stays alive (shared) when evicted meanwhile. One renderer's context only.
class SceneGpuCache {
 public:
  struct Stats {
    std::size_t bytes = 0, entries = 0, budget = 0;
    std::uint64_t hits = 0, misses = 0, evictions = 0;
  };
  explicit SceneGpuCache(std::size_t budget_bytes) : budget_(budget_bytes) {}
  // The entry under `key`, now the most recently used; null if none.
  template <class T>
  std::shared_ptr<const T> find(const std::string& key) {
    return std::static_pointer_cast<const T>(find_entry(key));
  }
  // Keeps `value` (of `bytes`) under `key`; an entry over the whole budget is
  // not kept.
  void put(const std::string& key, std::shared_ptr<const void> value, std::size_t bytes);
  // Evicts least recently used entries down to `bytes`.
  void shrink_to(std::size_t bytes);
  Stats stats() const;

 private:
  struct Entry {
    std::string key;
    std::shared_ptr<const void> value;
    std::size_t bytes = 0;
  };
  std::shared_ptr<const void> find_entry(const std::string& key);
  std::size_t budget_;
  std::size_t bytes_ = 0;
  std::list<Entry> lru_;  // most recently used first
  std::map<std::string, std::list<Entry>::iterator> index_;
  std::uint64_t hits_ = 0, misses_ = 0, evictions_ = 0;
};

}  // namespace beamcast
