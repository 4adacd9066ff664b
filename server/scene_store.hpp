// Scenes stored under an id (scene.put/update/delete), bounded by count and by
// bytes of scene JSON, least recently used evicted first. Thread-safe. Renders
// hold a shared_ptr, so deleting or evicting a scene never harms one in flight.
#pragma once

#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "protocol/render_request.hpp"  // StoredScene

namespace beamcast {

class SceneStore {
 public:
  SceneStore(int max_scenes, std::uint64_t max_bytes) : max_scenes_(max_scenes), max_bytes_(max_bytes) {}

  // Stores (replacing any scene of that id); returns the ids evicted to make room.
  std::vector<std::string> put(const std::string& id, std::shared_ptr<const StoredScene> scene);
  std::shared_ptr<const StoredScene> get(const std::string& id);  // null if absent
  bool erase(const std::string& id);
  std::vector<std::string> ids() const;  // most recently used first
  std::size_t count() const;
  std::uint64_t bytes() const;

 private:
  int max_scenes_;
  std::uint64_t max_bytes_;
  mutable std::mutex mu_;
  std::list<std::pair<std::string, std::shared_ptr<const StoredScene>>> lru_;  // front: newest
  std::uint64_t bytes_ = 0;
};

}  // namespace beamcast
